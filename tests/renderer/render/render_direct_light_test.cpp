// Direct lighting of a diffuse plane against closed-form irradiance, for every light type.
// The camera looks straight down on the plane y = 0; each pixel's expected value is the closed
// form integrated over the pixel's footprint (4x4 sub-pixel points through the same camera).
#include <gtest/gtest.h>

#include <functional>

#include "renderer/render/thin_lens_camera.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

constexpr float kAlbedo = 0.5f;
constexpr int kSize = 24;

SceneInput plane_scene() {
  SceneInput in;
  in.camera = camera_looking({0, 4, 0}, {0, 0, 0}, 40.f, {0, 0, -1});
  in.materials = {DiffuseParams{Spectrum(kAlbedo)}};
  in.objects = {quad_object({-20, 0, 20}, {40, 0, 0}, {0, 0, -40}, 0)};
  return in;
}

// Expected pixel values from irradiance E(x, z) on the plane.
Image expected_image(const SceneInput& in, const std::function<double(double, double)>& irradiance) {
  ThinLensCamera cam(in.camera, kSize, kSize);
  Image img(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      double sum = 0.0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const CameraRay r = cam.generate_ray(vec2(x + (i + 0.5f) / 4.f, y + (j + 0.5f) / 4.f), vec2(0.5f), 0.f);
          const float t = -r.origin.y / r.direction.y;
          const vec3 p = r.origin + t * r.direction;
          sum += kAlbedo / kPi * irradiance(p.x, p.z);
        }
      for (int c = 0; c < 3; ++c) img.pixel(x, y)[c] = float(sum / 16.0);
    }
  return img;
}

// Compares 4x4-pixel blocks: within `rel` relative error plus 4 standard errors of the noise.
void expect_matches(const RenderResult& r, const Image& expected, double rel) {
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  for (int by = 0; by < kSize; by += 4)
    for (int bx = 0; bx < kSize; bx += 4) {
      double mean, se, want = 0.0;
      region_mean(r, bx, by, bx + 4, by + 4, 1, &mean, &se);
      for (int y = by; y < by + 4; ++y)
        for (int x = bx; x < bx + 4; ++x) want += expected.pixel(x, y)[1] / 16.0;
      EXPECT_NEAR(mean, want, rel * want + 4.0 * se) << "block " << bx << "," << by;
    }
}

TEST(RenderDirectLight, PointLightMatchesInverseSquareCosineLaw) {
  SceneInput in = plane_scene();
  const vec3 light(0.7f, 1.5f, -0.4f);
  const float intensity = 3.f;
  in.lights = {PointLightDesc{light, Spectrum(intensity)}};
  const auto r = render_input(in, small_settings(kSize, kSize, 16));
  const Image want = expected_image(in, [&](double x, double z) {
    const double dx = light.x - x, dy = light.y, dz = light.z - z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    return intensity * dy / (d2 * std::sqrt(d2));
  });
  expect_matches(r, want, 0.01);
}

TEST(RenderDirectLight, DirectionalLightGivesIrradianceTimesCosine) {
  SceneInput in = plane_scene();
  const vec3 dir = glm::normalize(vec3(1, -2, 0.5f));
  in.lights = {DirectionalLightDesc{dir, Spectrum(2.f)}};
  const auto r = render_input(in, small_settings(kSize, kSize, 4));
  const Image want = expected_image(in, [&](double, double) { return 2.0 * -dir.y; });
  expect_matches(r, want, 1e-3);
}

TEST(RenderDirectLight, ConstantEnvironmentGivesAlbedoTimesRadiance) {
  SceneInput in = plane_scene();
  in.environment = Spectrum(0.8f);
  const auto r = render_input(in, small_settings(kSize, kSize, 64, 2));
  const Image want = expected_image(in, [&](double, double) { return kPi * 0.8; });
  expect_matches(r, want, 0.01);
}

// A sphere of radiance L wholly above the tangent plane acts as a point source of intensity
// pi r^2 L: E = pi L r^2 cos(beta) / D^2.
TEST(RenderDirectLight, SphereEmitterMatchesClosedForm) {
  SceneInput in = plane_scene();
  in.materials.push_back(DiffuseParams{Spectrum(0.f)});
  const vec3 c(3.f, 1.f, 0.5f);
  const float radius = 0.4f, radiance = 5.f;
  in.objects.push_back(sphere_object(c, radius, 1, Spectrum(radiance)));
  const auto r = render_input(in, small_settings(kSize, kSize, 32, 2));
  const Image want = expected_image(in, [&](double x, double z) {
    const double dx = c.x - x, dy = c.y, dz = c.z - z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    return kPi * radiance * radius * radius * (dy / std::sqrt(d2)) / d2;
  });
  expect_matches(r, want, 0.01);
}

// Configuration factor from a point to a parallel rectangle with one corner above it
// (Howell, "A Catalog of Radiation Heat Transfer Configuration Factors", B-3), X = a/h, Y = b/h.
double corner_factor(double a, double b, double h) {
  const double x = a / h, y = b / h;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * M_PI);
}
double signed_corner(double a, double b, double h) {
  return (a < 0 ? -1 : 1) * (b < 0 ? -1 : 1) * corner_factor(std::abs(a), std::abs(b), h);
}

TEST(RenderDirectLight, QuadEmitterMatchesConfigurationFactor) {
  SceneInput in = plane_scene();
  in.materials.push_back(DiffuseParams{Spectrum(0.f)});
  const float x0 = 2.f, x1 = 3.f, z0 = -0.5f, z1 = 0.5f, h = 1.f, radiance = 4.f;
  // u x v points down (-y): the emitting side faces the plane.
  in.objects.push_back(quad_object({x0, h, z0}, {x1 - x0, 0, 0}, {0, 0, z1 - z0}, 1, Spectrum(radiance)));
  const auto r = render_input(in, small_settings(kSize, kSize, 32, 2));
  const Image want = expected_image(in, [&](double x, double z) {
    const double f = signed_corner(x1 - x, z1 - z, h) - signed_corner(x0 - x, z1 - z, h) -
                     signed_corner(x1 - x, z0 - z, h) + signed_corner(x0 - x, z0 - z, h);
    return kPi * radiance * f;
  });
  expect_matches(r, want, 0.01);
}

TEST(RenderDirectLight, QuadEmitterIsOneSided) {
  SceneInput in = plane_scene();
  in.materials.push_back(DiffuseParams{Spectrum(0.f)});
  // Same quad with u and v swapped: its front faces up, away from the plane.
  in.objects.push_back(quad_object({2, 1, -0.5f}, {0, 0, 1}, {1, 0, 0}, 1, Spectrum(4.f)));
  const auto r = render_input(in, small_settings(kSize, kSize, 8, 2));
  EXPECT_EQ(image_stats(r.image).max, 0.0);
}

TEST(RenderDirectLight, MaxDepthOneShowsOnlyEmitters) {
  SceneInput in = plane_scene();
  in.lights = {PointLightDesc{{0, 1, 0}, Spectrum(3.f)}};
  in.environment = Spectrum(1.f);
  const auto r = render_input(in, small_settings(kSize, kSize, 4, 1));
  EXPECT_EQ(image_stats(r.image).max, 0.0);  // the plane fills the view; nothing emits towards us
}

TEST(RenderDirectLight, DistributedIntegratorMatchesForDiffuseDirectLight) {
  SceneInput in = plane_scene();
  const vec3 light(0.2f, 1.2f, 0.3f);
  in.lights = {PointLightDesc{light, Spectrum(2.f)}};
  RenderSettings s = small_settings(kSize, kSize, 16);
  s.integrator = IntegratorKind::kDistributed;
  const auto r = render_input(in, s);
  const Image want = expected_image(in, [&](double x, double z) {
    const double dx = light.x - x, dy = light.y, dz = light.z - z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    return 2.0 * dy / (d2 * std::sqrt(d2));
  });
  expect_matches(r, want, 0.01);
}

}  // namespace
}  // namespace penumbra::test
