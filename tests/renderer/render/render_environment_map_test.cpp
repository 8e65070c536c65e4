// Environment maps through the whole renderer: a constant map renders as the constant environment
// (furnace), a map bright on the upper hemisphere only gives the closed-form sky irradiance on a
// diffuse plane, a sky with a sun gives the irradiance of the map's own radiance by cubature (where
// the path integrator's MIS-compensated sampling leaves the sky to BSDF sampling), importance and
// uniform sampling agree, and a one-texel sun yields no NaN/Inf.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "renderer/lights/environment_map.h"

#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

constexpr int kSize = 24;

template <typename F>
EnvironmentMapDesc make_map(int width, int height, F f) {
  EnvironmentMapDesc d;
  d.width = width;
  d.height = height;
  auto rgb = std::make_shared<std::vector<float>>(size_t(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) (*rgb)[(size_t(y) * width + x) * 3 + c] = f(x, y, c);
  d.rgb = std::move(rgb);
  return d;
}

EnvironmentMapDesc constant_map(float value) {
  return make_map(16, 8, [=](int, int, int) { return value; });
}

// A diffuse plane y = 0 (front +y) filling the view of a camera looking straight down.
SceneInput plane_scene(float albedo) {
  SceneInput in;
  in.camera = camera_looking({0, 4, 0}, {0, 0, 0}, 40.f, {0, 0, -1});
  in.materials = {DiffuseParams{Spectrum(albedo)}};
  in.objects = {quad_object({-20, 0, 20}, {40, 0, 0}, {0, 0, -40}, 0)};
  return in;
}

// Every 4x4 block of channel c within `rel` of `want` plus 4 standard errors.
void expect_blocks_near(const RenderResult& r, int c, double want, double rel) {
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  for (int by = 0; by < r.image.height; by += 4)
    for (int bx = 0; bx < r.image.width; bx += 4) {
      double mean, se;
      region_mean(r, bx, by, bx + 4, by + 4, c, &mean, &se);
      EXPECT_NEAR(mean, want, rel * want + 4.0 * se) << "block " << bx << "," << by << " channel " << c;
    }
}

// Every 4x4 block and channel of two renders agrees within 4.5 combined standard errors.
void expect_same_to_noise(const RenderResult& a, const RenderResult& b) {
  EXPECT_EQ(a.stats.nonfinite_samples, 0u);
  EXPECT_EQ(b.stats.nonfinite_samples, 0u);
  for (int c = 0; c < 3; ++c)
    for (int by = 0; by < a.image.height; by += 4)
      for (int bx = 0; bx < a.image.width; bx += 4) {
        double ma, sa, mb, sb;
        region_mean(a, bx, by, bx + 4, by + 4, c, &ma, &sa);
        region_mean(b, bx, by, bx + 4, by + 4, c, &mb, &sb);
        EXPECT_NEAR(ma, mb, 4.5 * std::sqrt(sa * sa + sb * sb) + 1e-6)
            << "block " << bx << "," << by << " channel " << c;
      }
}

TEST(RenderEnvironmentMap, ConstantMapIsAWhiteFurnace) {
  SceneInput in = furnace_with_sphere(DiffuseParams{Spectrum(1.f)});
  in.environment = Spectrum(0.f);
  in.environment_map = constant_map(1.f);
  const auto r = render_input(in, small_settings(kSize, kSize, 64));
  const ImageStats st = image_stats(r.image);
  EXPECT_EQ(st.nonfinite, 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(st.mean[c], 1.0, 0.01);
  EXPECT_GT(st.min, 0.85);
  EXPECT_LT(st.max, 1.15);
}

// Glossy, rough-glass and diffuse objects lit by a constant map and by the constant environment
// of the same radiance: the same picture up to noise, for both integrators.
TEST(RenderEnvironmentMap, ConstantMapRendersAsConstantRadiance) {
  SceneInput in;
  in.camera = camera_looking({0, 1, 5}, {0, 0.5f, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.6f, 0.5f, 0.4f)}, ConductorParams{Spectrum(0.9f), 0.3f},
                  DielectricParams{1.5f, 0.2f, Spectrum(0.f)}};
  in.objects = {quad_object({-5, 0, 5}, {10, 0, 0}, {0, 0, -10}, 0),
                sphere_object({-0.8f, 0.5f, 0}, 0.5f, 1), sphere_object({0.8f, 0.5f, 0}, 0.5f, 2)};
  for (IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
    RenderSettings s = small_settings(kSize, kSize, 64, 6);
    s.integrator = kind;
    SceneInput constant = in, map = in;
    constant.environment = Spectrum(0.7f, 0.8f, 1.f);
    map.environment_map = make_map(16, 9, [&](int, int, int c) { return constant.environment[c]; });
    s.seed = 1;
    const auto a = render_input(constant, s);
    s.seed = 2;
    const auto b = render_input(map, s);
    expect_same_to_noise(a, b);
  }
}

// Sky of radiance L above the horizon only. Rows at v = y / (height - 1): with an odd height the
// middle row lies on the horizon, so the upper hemisphere is exactly L and an upward diffuse plane
// of albedo rho reflects rho L. A map upside down (row 0 at -y) would leave it black.
TEST(RenderEnvironmentMap, UpperHemisphereSkyGivesAlbedoTimesRadiance) {
  constexpr int height = 65;
  constexpr float radiance = 1.5f, albedo = 0.6f;
  SceneInput in = plane_scene(albedo);
  in.environment_map = make_map(32, height, [](int, int y, int) { return y <= height / 2 ? radiance : 0.f; });
  const auto r = render_input(in, small_settings(kSize, kSize, 64, 2));
  expect_blocks_near(r, 1, albedo * radiance, 0.005);
}

// The same sky tilted by alpha about z: an upward plane sees the view-factor irradiance
// pi L (1 + cos alpha) / 2, plus the thin band below the map's horizon where the lookup ramps
// from L to 0 over one row spacing d: to first order L d sin(alpha).
TEST(RenderEnvironmentMap, TiltedSkyGivesViewFactorIrradiance) {
  constexpr int height = 65;
  constexpr float radiance = 1.5f, albedo = 0.6f, alpha = 60.f;
  SceneInput in = plane_scene(albedo);
  in.environment_map = make_map(32, height, [](int, int y, int) { return y <= height / 2 ? radiance : 0.f; });
  in.environment_map->to_world = glm::mat3(glm::rotate(glm::mat4(1.f), glm::radians(alpha), vec3(0, 0, 1)));
  const double a = glm::radians(double(alpha)), d = M_PI / (height - 1);
  const double irradiance = M_PI * radiance * (1 + std::cos(a)) / 2 + radiance * d * std::sin(a);
  const auto r = render_input(in, small_settings(kSize, kSize, 64, 2));
  expect_blocks_near(r, 1, albedo / M_PI * irradiance, 0.005);
}

// The benchmark's uniform sampling must estimate the same image as importance sampling.
// A sky of 0.5 over the upper hemisphere with a sun of 12 texels at 12 (about 45 degrees up): the
// map's mean luminance (about 0.56) is above the whole sky, so the path integrator samples the map
// only at the sun and leaves the sky to the plane's cosine samples, whose MIS weight there must be
// 1 (EnvironmentMap::compensated). A diffuse plane facing up then shows albedo / pi times the
// irradiance, which a midpoint rule over the hemisphere computes from the map's own radiance().
// Both integrators; the distributed one samples the whole map. Escaped rays weighed against the
// full map's density instead of the twin's make the image 3.7% too dark here.
TEST(RenderEnvironmentMap, SkyWithASunGivesTheIrradianceOfTheMapsRadiance) {
  constexpr int width = 32, height = 17;
  constexpr float albedo = 0.7f;
  SceneInput in = plane_scene(albedo);
  in.environment_map = make_map(width, height, [](int x, int y, int) {
    if (y > height / 2) return 0.f;
    return (x >= 6 && x <= 8 && y >= 3 && y <= 6) ? 12.f : 0.5f;
  });
  const EnvironmentMap map(*in.environment_map);
  const float mean = float(map.luminance_integral() / (4.0 * M_PI));
  ASSERT_GT(mean, 0.52f);  // above the sky: the compensated density is the sun's alone
  ASSERT_LT(mean, 0.7f);   // but not far: the full density gives the sky much of its samples
  double irradiance = 0.0;
  constexpr int nt = 1200, np = 2400;
  for (int i = 0; i < nt; ++i) {
    const double theta = 0.5 * M_PI * (i + 0.5) / nt;
    const double weight = std::cos(theta) * std::sin(theta) * (0.5 * M_PI / nt) * (2.0 * M_PI / np);
    for (int j = 0; j < np; ++j) {
      const double phi = 2.0 * M_PI * (j + 0.5) / np;
      const vec3 d(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)), float(std::sin(theta) * std::sin(phi)));
      irradiance += weight * double(map.radiance(d)[1]);
    }
  }
  for (const IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
    SCOPED_TRACE(kind == IntegratorKind::kPath ? "path" : "distributed");
    RenderSettings s = small_settings(kSize, kSize, 256, 2);
    s.integrator = kind;
    const auto r = render_input(in, s);
    EXPECT_EQ(r.stats.nonfinite_samples, 0u);
    double m, se;
    region_mean(r, 0, 0, kSize, kSize, 1, &m, &se);
    EXPECT_NEAR(m, albedo / M_PI * irradiance, 0.002 * m + 4.0 * se);
  }
}

// A render builds the sampling table of the map it samples and no other: the path integrator the
// compensated twin's, the distributed integrator the full map's (each table is as large as the
// image; docs/environment-maps.md). Scene::prepare_sampling builds it before the render, as the
// CLI and the service do to count it as build time.
TEST(RenderEnvironmentMap, ARenderBuildsOnlyTheTableItSamples) {
  SceneInput in = plane_scene(0.5f);
  in.environment_map = make_map(32, 17, [](int x, int y, int) { return (x == 5 && y == 4) ? 50.f : 0.4f; });
  for (const IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
    SCOPED_TRACE(kind == IntegratorKind::kPath ? "path" : "distributed");
    const auto scene = Scene::build(in);
    const auto* full = dynamic_cast<const EnvironmentMap*>(scene->environment());
    const auto* twin = dynamic_cast<const EnvironmentMap*>(scene->mis_environment());
    ASSERT_NE(full, nullptr);
    ASSERT_NE(twin, nullptr);
    ASSERT_NE(full, twin);
    EXPECT_FALSE(full->sampling_table_built());
    EXPECT_FALSE(twin->sampling_table_built());
    (void)full->radiance(vec3(0, 1, 0));  // a lookup alone builds nothing
    EXPECT_FALSE(full->sampling_table_built());
    scene->prepare_sampling(kind);
    const bool path = kind == IntegratorKind::kPath;
    EXPECT_EQ(twin->sampling_table_built(), path);
    EXPECT_EQ(full->sampling_table_built(), !path);
    RenderSettings s = small_settings(8, 8, 4, 3);
    s.integrator = kind;
    EXPECT_EQ(render(*scene, s).stats.nonfinite_samples, 0u);
    EXPECT_EQ(twin->sampling_table_built(), path);
    EXPECT_EQ(full->sampling_table_built(), !path);
  }
}

TEST(RenderEnvironmentMap, UniformAndImportanceSamplingAgree) {
  SceneInput in = plane_scene(0.5f);
  in.camera = camera_looking({0, 2, 4}, {0, 0.3f, 0}, 45.f);
  in.materials.push_back(ConductorParams{Spectrum(0.9f), 0.2f});
  in.objects.push_back(sphere_object({0, 0.6f, 0}, 0.6f, 1));
  // A sky with a broad, moderately bright sun, so uniform sampling converges too.
  in.environment_map = make_map(32, 17, [](int x, int y, int c) {
    const float sun = (x >= 10 && x <= 12 && y >= 4 && y <= 5) ? 20.f : 0.f;
    return 0.3f + 0.1f * c + sun;
  });
  RenderSettings s = small_settings(kSize, kSize, 128, 4);
  s.seed = 3;
  const auto importance = render_input(in, s);
  in.environment_map->uniform_sampling = true;
  s.seed = 4;
  const auto uniform = render_input(in, s);
  expect_same_to_noise(importance, uniform);
}

// A one-texel sun of 1e6 on black, lighting a diffuse plane and a glass sphere: no sample may
// turn into NaN or Inf.
TEST(RenderEnvironmentMap, OneHotTexelProducesNoNonFiniteSamples) {
  SceneInput in = plane_scene(0.8f);
  in.camera = camera_looking({0, 2, 4}, {0, 0.3f, 0}, 45.f);
  in.materials.push_back(DielectricParams{1.5f, 0.f, Spectrum(0.f)});
  in.objects.push_back(sphere_object({0, 0.6f, 0}, 0.6f, 1));
  for (const auto [hx, hy] : {std::pair{20, 5}, std::pair{0, 0}, std::pair{63, 31}}) {
    in.environment_map = make_map(64, 32, [&](int x, int y, int) { return x == hx && y == hy ? 1e6f : 0.f; });
    const auto r = render_input(in, small_settings(16, 16, 16));
    EXPECT_EQ(r.stats.nonfinite_samples, 0u);
    EXPECT_EQ(image_stats(r.image).nonfinite, 0);
  }
}

}  // namespace
}  // namespace penumbra::test
