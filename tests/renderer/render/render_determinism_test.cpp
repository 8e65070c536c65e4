// The image for a given seed is a pure function of the scene and settings: the same for any
// thread count and tile size; a different seed gives a different image.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <utility>
#include <vector>

#include "renderer/render/pass_plan.h"

#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

SceneInput busy_scene() {
  SceneInput in;
  in.camera = camera_looking({0, 1, 4}, {0, 0.5f, 0}, 45.f);
  in.camera.aperture_radius = 0.05f;
  in.camera.shutter_close = 1.f;
  in.environment = Spectrum(0.2f);
  in.materials = {DiffuseParams{Spectrum(0.7f)}, DielectricParams{1.5f, 0.2f, Spectrum(0.3f)},
                  ConductorParams{Spectrum(0.9f), 0.3f}};
  in.objects = {quad_object({-3, 0, 3}, {6, 0, 0}, {0, 0, -6}, 0),
                sphere_object({-0.6f, 0.5f, 0}, 0.5f, 1), sphere_object({0.7f, 0.4f, 0.2f}, 0.4f, 2),
                quad_object({-0.5f, 2.5f, -0.5f}, {1, 0, 0}, {0, 0, 1}, 0, Spectrum(6.f))};
  in.objects[2].velocity = vec3(0.3f, 0, 0);
  in.lights = {PointLightDesc{{1, 2, 1}, Spectrum(2.f)}};
  return in;
}

TEST(RenderDeterminism, SameImageForAnyThreadCountAndTileSize) {
  const auto scene = Scene::build(busy_scene());
  RenderSettings s = small_settings(40, 30, 8, 6);
  s.seed = 42;
  s.threads = 1;
  s.tile_size = 16;
  const Image a = render(*scene, s).image;
  s.threads = 2;
  s.tile_size = 7;
  const Image b = render(*scene, s).image;
  s.threads = 0;
  s.tile_size = 64;
  const Image c = render(*scene, s).image;
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.rgb, c.rgb);
}

// A pass's work items are the tiles, or ranges of the pixel order where the window has few tiles
// for its threads (render.cpp, balanced_items): whatever the split, every pixel takes its samples
// once, and the image is the one tile-sized items give.
TEST(RenderDeterminism, EveryPixelSampledOnceWhateverTheWorkItems) {
  const auto scene = Scene::build(busy_scene());
  for (const auto [w, h] : {std::pair{1, 1}, std::pair{17, 3}, std::pair{40, 30}, std::pair{130, 20}}) {
    RenderSettings s = small_settings(w, h, 3, 4);
    s.tile_size = 1 << 20;  // one tile: the items are ranges of the pixel order
    Image first;
    for (const int threads : {1, 2, 3, 7, 64}) {
      s.threads = threads;
      const RenderResult r = render(*scene, s);
      EXPECT_EQ(r.stats.camera_samples, uint64_t(w) * h * 3) << w << "x" << h << ", " << threads;
      for (size_t i = 0; i < r.image.rgb.size(); ++i)
        ASSERT_GT(r.image.rgb[i], 0.f) << "value " << i << " unrendered, " << w << "x" << h << ", " << threads;
      if (first.rgb.empty())
        first = r.image;
      else
        EXPECT_EQ(r.image.rgb, first.rgb) << w << "x" << h << ", " << threads;
    }
    s.tile_size = 1;  // w x h tiles, as many items as pixels or fewer
    s.threads = 2;
    EXPECT_EQ(render(*scene, s).image.rgb, first.rgb) << w << "x" << h;
  }
}

// The passes a render makes: the largest RenderProgress::passes_done its progress reports saw
// (reports come after every tile, so the last pass's tiles report the passes before it).
struct PassCount {
  int passes = 0;
  RenderControl control() {
    RenderControl c;
    c.on_progress = [this](const RenderProgress& p) { passes = std::max(passes, p.passes_done + 1); };
    return c;
  }
};

// Passes are where previews, time budgets and adaptive limits need them, and nowhere else; the
// image does not depend on them.
TEST(RenderDeterminism, SameImageWhateverThePasses) {
  const auto scene = Scene::build(busy_scene());
  for (const float threshold : {0.f, 0.02f}) {
    SCOPED_TRACE(threshold);
    const bool adaptive = threshold > 0.f;
    RenderSettings s = small_settings(40, 30, 40, 6);
    s.seed = 7;
    s.tile_size = 8;
    s.noise_threshold = threshold;
    // Nothing asks for a boundary: uniform sampling in one pass, adaptive sampling's first pass
    // at its 16 samples, then 16 and 8 (to 40).
    PassCount plain;
    const RenderResult a = render(*scene, s, plain.control());
    EXPECT_EQ(plain.passes, adaptive ? 3 : 1);
    // A preview after each pass, passes doubling: 1, 1, 2, 4, 8, 16 and the 8 left.
    PassCount doubling;
    RenderControl c = doubling.control();
    c.min_pass_seconds = 0.0;
    int previews = 0;
    c.on_pass = [&](const Image&, const RenderProgress&) { ++previews; };
    const RenderResult b = render(*scene, s, c);
    EXPECT_EQ(previews, 7);
    EXPECT_EQ(doubling.passes, 7);
    // Previews with passes of at least a (long) time: one sample, then all the rest (uniform),
    // or the rest up to adaptive sampling's first decision at 16, then 16 and 8.
    PassCount timed;
    c = timed.control();
    c.min_pass_seconds = 1e3;
    previews = 0;
    c.on_pass = [&](const Image&, const RenderProgress&) { ++previews; };
    const RenderResult e = render(*scene, s, c);
    EXPECT_EQ(previews, adaptive ? 4 : 2);
    EXPECT_EQ(timed.passes, adaptive ? 4 : 2);
    // A time budget it does not reach: the same progressive passes.
    s.time_limit = 1000.0;
    PassCount budgeted;
    c = budgeted.control();
    c.min_pass_seconds = 0.0;
    const RenderResult d = render(*scene, s, c);
    EXPECT_EQ(budgeted.passes, 7);
    EXPECT_EQ(a.image.rgb, b.image.rgb);
    EXPECT_EQ(a.image.rgb, d.image.rgb);
    EXPECT_EQ(a.image.rgb, e.image.rgb);
    EXPECT_EQ(a.stats.spp_mean, b.stats.spp_mean);
    EXPECT_EQ(a.stats.spp_mean, d.stats.spp_mean);
    EXPECT_EQ(a.stats.spp_mean, e.stats.spp_mean);
    if (adaptive) {
      EXPECT_LT(a.stats.spp_min, a.stats.spp_max);  // adaptive did decide
    }
  }
}

// The pass sizes themselves, at a given rate: doubling, raised to last min_seconds where the
// boundaries are free, never past adaptive sampling's fixed boundaries, cut to what is left.
TEST(PassPlan, SizesDoubleRaisedToTheMinimumTimeUpToFixedBoundaries) {
  auto sizes = [](PassPlan plan, double seconds_per_sample) {
    std::vector<int> out;
    for (int done = 0, n = plan.next(0, 0.0); n > 0; n = plan.next(done, seconds_per_sample)) {
      out.push_back(n);
      done += n;
    }
    return out;
  };
  PassPlan uniform{.spp = 256, .first = 1, .fixed_from = INT_MAX, .min_seconds = 0.0};
  EXPECT_EQ(sizes(uniform, 0.01), (std::vector<int>{1, 1, 2, 4, 8, 16, 32, 64, 128}));
  uniform.min_seconds = 0.5;  // 50 samples at 0.01 s each
  EXPECT_EQ(sizes(uniform, 0.01), (std::vector<int>{1, 50, 51, 102, 52}));
  EXPECT_EQ(sizes(uniform, 1.0), (std::vector<int>{1, 1, 2, 4, 8, 16, 32, 64, 128}));
  EXPECT_EQ(sizes(uniform, 1e-9), (std::vector<int>{1, 255}));
  PassPlan adaptive{.spp = 256, .first = 1, .fixed_from = 16, .min_seconds = 0.5};
  EXPECT_EQ(sizes(adaptive, 0.01), (std::vector<int>{1, 15, 16, 32, 64, 128}));
  EXPECT_EQ(sizes(adaptive, 0.1), (std::vector<int>{1, 5, 6, 4, 16, 32, 64, 128}));
  adaptive.first = 16;
  adaptive.min_seconds = 0.0;
  EXPECT_EQ(sizes(adaptive, 0.01), (std::vector<int>{16, 16, 32, 64, 128}));
  const PassPlan one{.spp = 40, .first = 40};
  EXPECT_EQ(sizes(one, 0.0), (std::vector<int>{40}));
}

TEST(RenderDeterminism, DifferentSeedGivesDifferentNoise) {
  const auto scene = Scene::build(busy_scene());
  RenderSettings s = small_settings(40, 30, 4, 6);
  s.seed = 1;
  const Image a = render(*scene, s).image;
  s.seed = 2;
  const Image b = render(*scene, s).image;
  EXPECT_NE(a.rgb, b.rgb);
}

}  // namespace
}  // namespace penumbra::test
