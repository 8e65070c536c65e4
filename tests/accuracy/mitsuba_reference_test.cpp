// Accuracy against Mitsuba 3: every scene in tests/accuracy/scenes/ is rendered with penumbra and
// compared with its Mitsuba 3.9 reference (tests/accuracy/references/, made by
// tools/make_references.py, see docs/accuracy.md).
//
// The test looks for bias, not likeness: a difference counts only if the Monte Carlo noise cannot
// explain it. For the whole image and for every 16x16-pixel block and channel,
//   z = (penumbra mean - reference mean) / sqrt(se_penumbra^2 + se_reference^2),
// where se_penumbra comes from the film's per-pixel variance estimates (sample variance / n,
// pixels independent) of several renders with different seeds, and se_reference from the
// reference's own stderr image (spread of its independent batches). With a stratified or
// low-discrepancy sampler the sample variance overestimates the error, so z is conservative.
// Renders are seeded, so the outcome is deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/io/image_io.h"
#include "renderer/render/render.h"
#include "renderer/render/window_merge.h"
#include "renderer/scene/scene.h"

namespace penumbra::test {
namespace {

constexpr int kSeeds = 4;           // independent renders per scene
constexpr int kSpp = 64;            // samples per pixel of each
constexpr int kBlock = 16;          // block edge in pixels
constexpr double kMaxImageZ = 4.0;  // whole-image mean, per channel
constexpr double kMaxBlockZ = 5.0;  // every block and channel (~1000 of them over all scenes)
constexpr double kMaxMeanZ2 = 2.0;  // mean of z^2 over a scene's blocks: catches small, spread bias

const std::vector<std::string> kScenes = {"all_lights", "conductors",   "cornell",      "dof",
                                          "furnace",    "glass_rough",  "glass_smooth", "kitchen_sink",
                                          "mesh_100k",  "mesh_files",   "motion_blur",  "plastics",
                                          "environment_map", "textured_diffuse", "textured_roughness",
                                          "normal_map", "instances", "many_lights"};

std::string accuracy_dir() { return std::string(PENUMBRA_SOURCE_DIR) + "/tests/accuracy/"; }

// A rectangle of pixels [x0, x1) x [y0, y1).
struct Region {
  int x0, y0, x1, y1;
  int pixels() const { return (x1 - x0) * (y1 - y0); }
};

// Sum of one channel over a region.
double region_sum(const Image& img, const Region& r, int c) {
  double s = 0.0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) s += img.pixel(x, y)[c];
  return s;
}

// Blocks of kBlock x kBlock pixels covering the image; partial blocks at the right and bottom
// edges are kept if at least half a block wide/high, otherwise merged into their neighbour.
std::vector<Region> blocks(int width, int height) {
  auto cuts = [](int n) {
    std::vector<int> c;
    for (int v = 0; v + kBlock <= n; v += kBlock) c.push_back(v);
    if (n - c.back() - kBlock >= kBlock / 2) c.push_back(c.back() + kBlock);
    c.push_back(n);
    return c;
  };
  const std::vector<int> xs = cuts(width), ys = cuts(height);
  std::vector<Region> out;
  for (size_t j = 0; j + 1 < ys.size(); ++j)
    for (size_t i = 0; i + 1 < xs.size(); ++i) out.push_back({xs[i], ys[j], xs[i + 1], ys[j + 1]});
  return out;
}

struct Comparison {
  double z = 0.0;
  double penumbra = 0.0;
  double reference = 0.0;
};

// One render of the whole image: the image and the variance of its pixels' means.
using RenderFn = std::function<RenderResult(const Scene&, const RenderSettings&)>;

void expect_no_bias_beyond_noise(const std::string& name, const RenderFn& render_image,
                                 int spp = kSpp, float noise_threshold = 0.f) {
  const api::LoadResult loaded = api::load_scene_file(accuracy_dir() + "scenes/" + name + ".json");
  ASSERT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors.front().to_string());
  const Image reference = read_image_file(accuracy_dir() + "references/" + name + ".exr");
  const Image reference_se = read_image_file(accuracy_dir() + "references/" + name + ".stderr.exr");
  RenderSettings settings = loaded.request->settings;
  ASSERT_EQ(reference.width, settings.width);
  ASSERT_EQ(reference.height, settings.height);
  const auto scene = Scene::build(loaded.request->scene);

  // Mean image over the seeds and the variance of that mean.
  const size_t n = reference.rgb.size();
  Image mean(settings.width, settings.height), variance(settings.width, settings.height);
  settings.spp = spp;
  settings.noise_threshold = noise_threshold;
  for (int seed = 0; seed < kSeeds; ++seed) {
    settings.seed = 1000 + seed;
    const RenderResult r = render_image(*scene, settings);
    ASSERT_EQ(r.stats.nonfinite_samples, 0u);
    for (size_t i = 0; i < n; ++i) {
      mean.rgb[i] += r.image.rgb[i] / kSeeds;
      variance.rgb[i] += r.variance.rgb[i] / (kSeeds * kSeeds);
    }
  }
  Image reference_var = reference_se;
  for (float& v : reference_var.rgb) v *= v;

  auto compare = [&](const Region& r, int c) {
    const double k = r.pixels();
    const double var = (region_sum(variance, r, c) + region_sum(reference_var, r, c)) / (k * k);
    Comparison cmp;
    cmp.penumbra = region_sum(mean, r, c) / k;
    cmp.reference = region_sum(reference, r, c) / k;
    cmp.z = (cmp.penumbra - cmp.reference) / std::sqrt(std::max(var, 1e-20));
    return cmp;
  };

  const Region whole{0, 0, settings.width, settings.height};
  double max_image_z = 0.0, max_block_z = 0.0;
  for (int c = 0; c < 3; ++c) {
    const Comparison cmp = compare(whole, c);
    max_image_z = std::max(max_image_z, std::abs(cmp.z));
    EXPECT_LE(std::abs(cmp.z), kMaxImageZ) << name << " image mean, channel " << c << ": penumbra "
                                           << cmp.penumbra << ", Mitsuba " << cmp.reference;
  }
  double sum_z2 = 0.0;
  int count = 0;
    for (const Region& r : blocks(settings.width, settings.height))
    for (int c = 0; c < 3; ++c) {
      const Comparison cmp = compare(r, c);
      sum_z2 += cmp.z * cmp.z;
      max_block_z = std::max(max_block_z, std::abs(cmp.z));
      ++count;
      EXPECT_LE(std::abs(cmp.z), kMaxBlockZ)
          << name << " block x " << r.x0 << ".." << r.x1 << ", y " << r.y0 << ".." << r.y1 << ", channel " << c
          << ": penumbra " << cmp.penumbra << ", Mitsuba " << cmp.reference << ", z = " << cmp.z;
    }
  EXPECT_LE(sum_z2 / count, kMaxMeanZ2) << name << ": mean z^2 over " << count << " block-channels";
  // The margins, for the log: how far from the thresholds this scene is.
  std::printf("%s: max |z| image %.2f (limit %.0f), block %.2f (limit %.0f), mean z^2 %.2f (limit %.0f)\n",
              name.c_str(), max_image_z, kMaxImageZ, max_block_z, kMaxBlockZ, sum_z2 / count, kMaxMeanZ2);
}

class MitsubaReference : public ::testing::TestWithParam<std::string> {};

// environment_map's floor holds sun caustics through its glass spheres: a few rare paths carry
// much of some blocks' light, and four renders of 64 samples often miss them in the mean and in
// the variance estimate alike. At 64 spp a block's |z| passed 5 (or the mean z^2 2) for 2 of 12
// seed sets with Sobol points and 3 of 12 with CMJ points (session 38's first CMJ permutation);
// at 256 spp for none (largest block |z| 2.8 with CMJ, 4.9 with Sobol).
int reference_spp(const std::string& scene) { return scene == "environment_map" ? 256 : kSpp; }

TEST_P(MitsubaReference, NoBiasBeyondNoise) {
  expect_no_bias_beyond_noise(
      GetParam(), [](const Scene& scene, const RenderSettings& settings) { return render(scene, settings); },
      reference_spp(GetParam()));
}

INSTANTIATE_TEST_SUITE_P(Scenes, MitsubaReference, ::testing::ValuesIn(kScenes),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// A frame split into three windows rendered apart with adaptive sampling, which then decides
// within each window (docs/animation-and-windows.md), merged: no bias beyond noise either. The
// variance of each pixel is its own window's estimate. The cornell box failed the mean-z^2 check
// here (2.33) and for the whole frame (2.57) while a pixel's own deviation helped decide its
// sample count, and glass_smooth failed it once the path integrator left the constant environment
// to BSDF sampling; since a pixel's count depends on its neighbours' samples alone
// (renderer/render/adaptive_sampling.cpp) both pass (docs/animation-and-windows.md).
RenderResult render_adaptive_split(const Scene& scene, const RenderSettings& settings) {
  const int w = settings.width, h = settings.height;
  const PixelWindow windows[3] = {{0, 0, w, h / 3}, {0, h / 3, w / 2, h}, {w / 2, h / 3, w, h}};
  std::vector<WindowPart> parts, variances;
  for (const PixelWindow& window : windows) {
    RenderSettings s = settings;
    s.window = window;
    RenderResult r = render(scene, s);
    EXPECT_EQ(r.stats.nonfinite_samples, 0u);
    EXPECT_LT(r.stats.spp_min, s.spp) << "adaptive sampling took every sample: the test tests nothing";
    parts.push_back({"image", window, std::move(r.image), {}});
    variances.push_back({"variance", window, std::move(r.variance), {}});
  }
  RenderResult merged;
  merged.image = merge_windows(parts, w, h).image;
  merged.variance = merge_windows(variances, w, h).image;
  return merged;
}

class MitsubaReferenceSplitAdaptive : public ::testing::TestWithParam<std::string> {};

TEST_P(MitsubaReferenceSplitAdaptive, NoBiasBeyondNoise) {
  expect_no_bias_beyond_noise(GetParam(), render_adaptive_split, 256, 0.05f);
}

INSTANTIATE_TEST_SUITE_P(Scenes, MitsubaReferenceSplitAdaptive,
                         ::testing::Values("dof", "glass_smooth", "motion_blur", "textured_diffuse", "all_lights", "cornell", "glass_rough", "conductors"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace penumbra::test
