// Path reuse (renderer/render/path_reuse.h) against plain path tracing: the same expected image,
// less noise per sample.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

// An empty Cornell box (tests/accuracy/scenes/cornell.json without its two boxes): its concave
// corners and the light 2 cm below the ceiling are where a wrong change of measure at the second
// vertex shows (the cosine there differs between the block's first vertices).
SceneInput empty_cornell_box() {
  SceneInput in;
  in.camera = camera_looking({0, 1, 3.6f}, {0, 1, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.73f)}, DiffuseParams{Spectrum(0.63f, 0.065f, 0.05f)},
                  DiffuseParams{Spectrum(0.14f, 0.45f, 0.091f)}};
  in.objects.push_back(quad_object({-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, 0));
  in.objects.push_back(quad_object({-1, 2, -1}, {2, 0, 0}, {0, 0, 2}, 0));
  in.objects.push_back(quad_object({-1, 0, -1}, {2, 0, 0}, {0, 2, 0}, 0));
  in.objects.push_back(quad_object({-1, 0, -1}, {0, 2, 0}, {0, 0, 2}, 1));
  in.objects.push_back(quad_object({1, 0, -1}, {0, 0, 2}, {0, 2, 0}, 2));
  in.objects.push_back(
      quad_object({-0.25f, 1.98f, -0.25f}, {0.5f, 0, 0}, {0, 0, 0.5f}, 0, Spectrum(17, 12, 4)));
  return in;
}

// The same box with a rough conductor floor and a rough plastic back wall: first vertices whose
// BSDF is evaluated through SurfaceBsdf (the Lambertian ones are inline) along the corner they
// make, and second vertices there that keep their own paths. And a two-sided shelf at the
// camera's height, edge-on: blocks across its line see its lit top and its dark underside.
SceneInput glossy_box() {
  SceneInput in = empty_cornell_box();
  in.objects.push_back(quad_object({-0.6f, 1.f, -0.9f}, {1.2f, 0, 0}, {0, 0, 0.6f}, 0));
  in.materials.push_back(ConductorParams{Spectrum(0.9f, 0.6f, 0.4f), 0.5f});
  in.materials.push_back(PlasticParams{Spectrum(0.2f, 0.5f, 0.3f), 1.5f, 0.4f});
  in.objects[0].material = 3;
  in.objects[2].material = 4;
  return in;
}

struct RowCheck {
  double worst_z = 0.0;
  int worst_row = -1;
};

// Each row's means over the left quarter, the middle half and the right quarter of the columns,
// reuse against plain, in standard errors (the film's per-pixel variances; a reuse block's
// pixels are correlated, so its error is counted twice over).
RowCheck compare_rows(const RenderResult& reuse, const RenderResult& plain) {
  RowCheck check;
  const int w = reuse.image.width, h = reuse.image.height;
  const int bands[4] = {0, w / 4, 3 * w / 4, w};
  for (int y = 0; y < h; ++y)
    for (int band = 0; band < 3; ++band)
      for (int c = 0; c < 3; ++c) {
        double a, sa, b, sb;
        region_mean(reuse, bands[band], y, bands[band + 1], y + 1, c, &a, &sa);
        region_mean(plain, bands[band], y, bands[band + 1], y + 1, c, &b, &sb);
        const double se = std::sqrt(4.0 * sa * sa + sb * sb) + 1e-4 * std::abs(b);
        const double z = std::abs(a - b) / se;
        if (z > check.worst_z) {
          check.worst_z = z;
          check.worst_row = y;
        }
      }
  return check;
}

// The mean over the pixels of each one's variance relative to its square (with relMSE's 0.01
// floor), from the film's own estimates.
double mean_relative_variance(const RenderResult& r) {
  double sum = 0.0;
  for (size_t i = 0; i < r.variance.rgb.size(); ++i) {
    const double m = r.image.rgb[i];
    sum += r.variance.rgb[i] / (m * m + 0.01);
  }
  return sum / double(r.variance.rgb.size());
}

// A render with path reuse `block` against a plain one of another seed, 1024 spp at 64 x 64:
// the worst row band's difference in standard errors.
RowCheck reuse_against_plain(const SceneInput& input, int block) {
  const auto scene = Scene::build(input);
  RenderSettings plain = small_settings(64, 64, 1024, 8);
  plain.seed = 7;
  RenderSettings reuse = plain;
  reuse.path_reuse = block;
  reuse.seed = 8;
  const RenderResult a = render(*scene, reuse);
  EXPECT_EQ(a.stats.nonfinite_samples, 0u);
  return compare_rows(a, render(*scene, plain));
}

TEST(PathReuse, SameExpectedImageAsPlainPathTracingRowByRow) {
  const RowCheck check = reuse_against_plain(empty_cornell_box(), 2);
  EXPECT_LT(check.worst_z, 5.0) << "row " << check.worst_row;
}

TEST(PathReuse, SameExpectedImageWithGlossyFirstVertices) {
  const RowCheck check = reuse_against_plain(glossy_box(), 4);
  EXPECT_LT(check.worst_z, 5.0) << "row " << check.worst_row;
}

TEST(PathReuse, LessNoisePerSampleWhereIndirectLightDominates) {
  const auto scene = Scene::build(empty_cornell_box());
  RenderSettings plain = small_settings(32, 32, 256, 8);
  RenderSettings reuse = plain;
  reuse.path_reuse = 2;
  const double v_plain = mean_relative_variance(render(*scene, plain));
  const double v_reuse = mean_relative_variance(render(*scene, reuse));
  // Measured 0.5-0.6 on this box; nothing shared would read 1.
  EXPECT_LT(v_reuse, 0.8 * v_plain) << v_reuse << " against " << v_plain;
}

TEST(PathReuse, OffWhenTheRenderCannotReuse) {
  // The distributed integrator, or Russian roulette at the first vertex: the image is the plain
  // one to the bit.
  const auto scene = Scene::build(empty_cornell_box());
  for (const bool distributed : {true, false}) {
    RenderSettings plain = small_settings(16, 16, 16, 8);
    if (distributed) plain.integrator = IntegratorKind::kDistributed;
    else plain.rr_depth = 1;
    RenderSettings reuse = plain;
    reuse.path_reuse = 3;
    EXPECT_EQ(render(*scene, reuse).image.rgb, render(*scene, plain).image.rgb) << distributed;
  }
}

}  // namespace
}  // namespace penumbra::test
