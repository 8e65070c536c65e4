// Camera geometry: vertical field of view, image x to the right, thin-lens focus.
#include <gtest/gtest.h>

#include "renderer/render/thin_lens_camera.h"

namespace penumbra::test {
namespace {

CameraDesc desc(float aperture) {
  CameraDesc d;
  d.position = {1, 2, 3};
  d.look_at = {1, 2, -1};
  d.up = {0, 1, 0};
  d.fov_degrees = 60.f;
  d.aperture_radius = aperture;
  d.focus_distance = 2.5f;
  return d;
}

TEST(ThinLensCamera, VerticalFieldOfViewAndOrientation) {
  ThinLensCamera cam(desc(0.f), 200, 100);
  const CameraRay top = cam.generate_ray({100.f, 0.f}, {0.5f, 0.5f}, 0.f);
  const float angle = std::acos(glm::dot(top.direction, vec3(0, 0, -1)));
  EXPECT_NEAR(angle, glm::radians(30.f), 1e-5f);
  EXPECT_GT(top.direction.y, 0.f);  // row 0 is the top of the image
  const CameraRay right = cam.generate_ray({200.f, 50.f}, {0.5f, 0.5f}, 0.f);
  EXPECT_GT(right.direction.x, 0.f);  // image x points right of the view direction
  EXPECT_NEAR(right.direction.y, 0.f, 1e-6f);
}

TEST(ThinLensCamera, LensRaysConvergeOnThePlaneOfFocus) {
  ThinLensCamera pinhole(desc(0.f), 64, 64);
  ThinLensCamera lens(desc(0.2f), 64, 64);
  const vec2 film(10.3f, 50.7f);
  const CameraRay chief = pinhole.generate_ray(film, {0.5f, 0.5f}, 0.f);
  // The plane of focus is perpendicular to the view axis at focus_distance.
  const vec3 focus = chief.origin + chief.direction * (2.5f / -chief.direction.z);
  for (float u : {0.1f, 0.4f, 0.9f})
    for (float v : {0.05f, 0.6f}) {
      const CameraRay r = lens.generate_ray(film, {u, v}, 0.f);
      EXPECT_NE(r.origin, chief.origin);
      EXPECT_LE(glm::length(r.origin - chief.origin), 0.2f + 1e-6f);
      const float t = (focus.z - r.origin.z) / r.direction.z;
      EXPECT_NEAR(glm::length(r.origin + t * r.direction - focus), 0.f, 1e-5f);
    }
}

}  // namespace
}  // namespace penumbra::test
