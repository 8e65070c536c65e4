// The Embree-only benchmark of `penumbra bench`: the three calling forms trace the same rays
// and must find the same hits, and the rays are the kinds it claims (a shadow and a bounce ray
// for every camera ray that hits).
#include <gtest/gtest.h>

#include "renderer/render/embree_ray_forms.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

// A floor seen at an angle (the upper part of the image is sky), a sphere on it that shadows
// part of it from a small light above.
SceneInput floor_sphere_light() {
  SceneInput in;
  in.camera = camera_looking({0.f, 1.5f, 4.f}, {0.f, 0.5f, 0.f}, 45.f);
  in.materials = {MaterialParams{}};
  in.objects = {quad_object({-2.f, 0.f, 2.f}, {4.f, 0.f, 0.f}, {0.f, 0.f, -4.f}, 0),
                sphere_object({0.f, 0.5f, 0.f}, 0.5f, 0),
                quad_object({-0.1f, 3.f, -0.1f}, {0.f, 0.f, 0.2f}, {0.2f, 0.f, 0.f}, 0, Spectrum(10.f))};
  return in;
}

TEST(EmbreeRayForms, FormsFindTheSameHitsOnEveryKindOfRay) {
  const auto scene = Scene::build(floor_sphere_light());
  const RenderSettings settings = small_settings(37, 23, 3);  // not a multiple of 16 rays
  const std::vector<RayFormResult> r = trace_embree_ray_forms(*scene, settings);
  ASSERT_EQ(r.size(), 9u);
  for (size_t kind = 0; kind < 3; ++kind) {
    for (size_t form = 0; form < 3; ++form) {
      const RayFormResult& x = r[3 * kind + form];
      EXPECT_EQ(int(x.kind), int(kind));
      EXPECT_EQ(int(x.form), int(form));
      EXPECT_GT(x.seconds, 0.0);
      EXPECT_EQ(x.rays, r[3 * kind].rays);
      EXPECT_EQ(x.hits, r[3 * kind].hits) << ray_kind_name(x.kind) << " rays, " << ray_form_name(x.form);
    }
  }
  const RayFormResult &camera = r[0], &shadow = r[3], &bounce = r[6];
  EXPECT_EQ(camera.rays, uint64_t(37 * 23 * 3));
  // Some camera rays see the sky, the others the floor or the sphere; each hit spawns one shadow and
  // one bounce ray.
  EXPECT_GT(camera.hits, camera.rays / 4);
  EXPECT_LT(camera.hits, camera.rays);
  EXPECT_EQ(shadow.rays, camera.hits);
  EXPECT_EQ(bounce.rays, camera.hits);
  // The sphere shadows part of the floor (and itself); the rest sees the light.
  EXPECT_GT(shadow.hits, 0u);
  EXPECT_LT(shadow.hits, shadow.rays / 2);
}

}  // namespace
}  // namespace penumbra::test
