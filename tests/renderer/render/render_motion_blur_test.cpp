// Motion blur: a moving emitter's image is its time average over the shutter, following the
// exact quadratic path position(t) = p + v t + a t^2 / 2.
#include <gtest/gtest.h>

#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

struct Moments {
  double flux = 0, cx = 0, cy = 0;
};

Moments image_moments(const Image& img) {
  Moments m;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const double v = img.pixel(x, y)[0];
      m.flux += v;
      m.cx += v * (x + 0.5);
      m.cy += v * (y + 0.5);
    }
  m.cx /= m.flux;
  m.cy /= m.flux;
  return m;
}

SceneInput emitter_scene(const ShapeDesc& shape, const vec3& v, const vec3& a, float open, float close) {
  SceneInput in;
  in.camera = camera_looking({0, 0, 10}, {0, 0, 0}, 30.f);
  in.camera.shutter_open = open;
  in.camera.shutter_close = close;
  in.materials = {DiffuseParams{Spectrum(0.f)}};
  ObjectDesc o;
  o.shape = shape;
  o.emission = Spectrum(1.f);
  o.velocity = v;
  o.acceleration = a;
  in.objects = {o};
  return in;
}

// With the camera looking down -z and motion in the z = 0 plane, screen position is linear in
// world position: the image centroid is the projection of the time-averaged position.
void check_centroid(const ShapeDesc& shape, const vec3& start) {
  const vec3 v(1.5f, 0.5f, 0.f), a(0.f, -3.f, 0.f);
  const float open = 0.25f, close = 1.25f;
  const auto moving = render_input(emitter_scene(shape, v, a, open, close), small_settings(96, 96, 256, 1));
  const auto still = render_input(emitter_scene(shape, vec3(0.f), vec3(0.f), 0.f, 0.f), small_settings(96, 96, 64, 1));
  const Moments m = image_moments(moving.image), s = image_moments(still.image);
  // Time average of v t + a t^2 / 2 over [open, close].
  auto avg = [&](float vv, float aa) {
    const double i1 = (close * close - open * open) / 2.0, i2 = (std::pow(close, 3) - std::pow(open, 3)) / 6.0;
    return (vv * i1 + aa * i2) / (close - open);
  };
  const double px_per_unit = 96.0 / (2.0 * 10.0 * std::tan(glm::radians(15.0)));
  EXPECT_NEAR(m.cx - s.cx, avg(v.x, a.x) * px_per_unit, 0.3);
  EXPECT_NEAR(m.cy - s.cy, -avg(v.y, a.y) * px_per_unit, 0.3);  // image y points down
  EXPECT_NEAR(m.flux / s.flux, 1.0, 0.02);
  (void)start;
}

TEST(RenderMotionBlur, SphereFollowsQuadraticPath) {
  check_centroid(SphereDesc{{-1.f, 0.5f, 0.f}, 0.4f}, {-1.f, 0.5f, 0.f});
}

TEST(RenderMotionBlur, MeshFollowsQuadraticPath) {
  // A camera-facing quad as a mesh (two triangles, counter-clockwise towards +z).
  MeshDesc m;
  m.positions = {{-1.4f, 0.1f, 0}, {-0.6f, 0.1f, 0}, {-0.6f, 0.9f, 0}, {-1.4f, 0.9f, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  check_centroid(m, {-1.f, 0.5f, 0.f});
}

TEST(RenderMotionBlur, ZeroShutterPlacesObjectAtShutterTime) {
  // shutter [1, 1]: no blur, the sphere sits at p + v + a/2.
  const vec3 v(1.f, 0.f, 0.f), a(0.f, -2.f, 0.f);
  const auto at1 = render_input(emitter_scene(SphereDesc{{0, 0, 0}, 0.4f}, v, a, 1.f, 1.f), small_settings(64, 64, 16, 1));
  const auto moved = render_input(emitter_scene(SphereDesc{{1.f, -1.f, 0}, 0.4f}, vec3(0.f), vec3(0.f), 0.f, 0.f),
                                  small_settings(64, 64, 16, 1));
  EXPECT_EQ(at1.image.rgb, moved.image.rgb);
}

}  // namespace
}  // namespace penumbra::test
