// The two user controls of the render loop: adaptive sampling (noise_threshold) and the time
// budget (time_limit). Both must keep the image correct (unbiased, finite) and adaptive
// sampling must stay deterministic whatever the thread count.
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "tests/stress/stress_util.h"

namespace penumbra::test {
namespace {

// Half the image is a flat, directly lit floor (converges at once), half a glossy/glass region
// lit indirectly (noisy).
SceneInput mixed_scene() {
  SceneInput in;
  in.camera = camera_looking({0, 1.2f, 3}, {0, 0.4f, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.6f)}, DielectricParams{1.5f, 0.2f, Spectrum(0.f)},
                  ConductorParams{Spectrum(0.9f), 0.3f}};
  in.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0), sphere({0.5f, 0.4f, 0}, 0.4f, 1),
                sphere({-0.5f, 0.4f, -0.2f}, 0.4f, 2),
                quad({-0.3f, 2, 0.3f}, {0, 0, -0.6f}, {0.6f, 0, 0}, 0, Spectrum(10.f))};
  in.lights = {DirectionalLightDesc{{0.3f, -1, -0.2f}, Spectrum(1.f)}};
  return in;
}

TEST(AdaptiveSampling, StopsEasyPixelsKeepsTheImageAndIsDeterministic) {
  const SceneInput in = mixed_scene();
  RenderSettings uniform = settings(32, 32, 256, 8, 4);
  RenderSettings adaptive = uniform;
  adaptive.noise_threshold = 0.05f;
  const RenderResult u = render_input(in, uniform);
  const RenderResult a = render_input(in, adaptive);
  EXPECT_EQ(nonfinite_count(a), 0);
  EXPECT_EQ(a.stats.spp_max, 256);
  EXPECT_LT(a.stats.spp_min, 64);
  EXPECT_LT(a.stats.spp_mean, 0.8 * 256);
  // Same picture within noise (unbiased: stopping depends on the samples so far only).
  const BlockComparison cmp = compare_blocks(u, a, 8, 5.0, 0.02);
  EXPECT_EQ(cmp.bad, 0) << cmp.first_bad;
  // Convergence is decided between passes: any thread count gives the same image.
  RenderSettings one_thread = adaptive;
  one_thread.threads = 1;
  one_thread.tile_size = 7;
  EXPECT_EQ(render_input(in, one_thread).image.rgb, a.image.rgb);
}

// render.noise_threshold is the relative RMS error the image aims for (relMSE with the 0.01
// floor, renderer/adaptive_sampling.h): the render's own estimate must meet it without spending
// the whole cap, and the true error against a long render must not exceed it (the variance
// estimate is conservative under QMC, so the true error is usually well below).
TEST(AdaptiveSampling, TheImageReachesTheTargetRelativeError) {
  const SceneInput in = mixed_scene();
  constexpr float t = 0.05f;
  RenderSettings adaptive = settings(24, 24, 8192, 8, 3);
  adaptive.noise_threshold = t;
  const RenderResult a = render_input(in, adaptive);
  double estimated = 0.0, actual = 0.0;
  const RenderResult ref = render_input(in, settings(24, 24, 4096, 8, 9));
  for (size_t i = 0; i < a.image.rgb.size(); ++i) {
    const double m = a.image.rgb[i], r = ref.image.rgb[i];
    estimated += a.variance.rgb[i] / (m * m + 1e-2);
    // minus the reference's own variance, so its noise is not charged to the adaptive image
    actual += ((m - r) * (m - r) - ref.variance.rgb[i]) / (r * r + 1e-2);
  }
  estimated /= double(a.image.rgb.size());
  actual /= double(a.image.rgb.size());
  EXPECT_LE(estimated, t * t);
  EXPECT_GE(estimated, 0.3 * t * t);  // and it stopped near the target, not far past it
  EXPECT_LE(actual, 1.2 * t * t);
  EXPECT_LT(a.stats.spp_mean, 0.5 * 8192);
  EXPECT_EQ(a.stats.spp_min, 16);  // the lit floor's easy pixels stop at the first estimate
}

TEST(TimeLimit, StopsEarlyWithAFiniteCompleteImage) {
  const SceneInput in = mixed_scene();
  RenderSettings s = settings(48, 48, 1 << 20, 8);
  s.time_limit = 0.5;
  const RenderResult r = render_input(in, s);
  EXPECT_TRUE(r.stats.stopped_by_time_limit);
  EXPECT_LT(r.stats.seconds, 5.0);
  EXPECT_EQ(nonfinite_count(r), 0);
  EXPECT_GE(r.stats.spp_min, 1);  // every pixel has at least the first pass
  // The budget stops between tiles, so pixels may differ by one pass in sample count; each
  // pixel's mean of the samples it has is still unbiased: compare with a full 64 spp render.
  const RenderResult ref = render_input(in, settings(48, 48, 64, 8));
  const BlockComparison cmp = compare_blocks(ref, r, 8, 6.0, 0.05);
  EXPECT_EQ(cmp.bad, 0) << cmp.first_bad;
}

// Progress under a time budget follows the budget: the fraction reaches the share of the time
// spent, and the ETA never promises more than what is left of it (not the hours that 2^20 spp
// would take).
TEST(TimeLimit, ProgressAndEtaFollowTheBudget) {
  const SceneInput in = mixed_scene();
  RenderSettings s = settings(48, 48, 1 << 20, 8);
  s.time_limit = 0.6;
  std::mutex m;
  std::vector<RenderProgress> seen;
  RenderControl control;
  control.on_progress = [&](const RenderProgress& p) {
    std::lock_guard lock(m);
    seen.push_back(p);
  };
  render(*Scene::build(in), s, control);
  ASSERT_FALSE(seen.empty());
  double last_fraction = 0;
  for (const RenderProgress& p : seen) {
    EXPECT_LE(p.eta_seconds, std::max(0.0, s.time_limit - p.elapsed_seconds) + 1e-9);
    EXPECT_GE(p.fraction, std::min(1.0, p.elapsed_seconds / s.time_limit) - 1e-9);
    last_fraction = std::max(last_fraction, p.fraction);
  }
  EXPECT_GT(last_fraction, 0.5);
}

}  // namespace
}  // namespace penumbra::test
