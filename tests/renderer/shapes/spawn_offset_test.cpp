// Rays spawned from a surface never hit that surface again by rounding error: reflected rays
// leave convex and flat surfaces cleanly, refracted rays reach the far side of a sphere, at
// scene scales from 1e-3 to 1e6 and far from the origin, static and moving.
#include <gtest/gtest.h>

#include <random>

#include "renderer/core/frame.h"
#include "renderer/sampling/sampling.h"
#include "renderer/scene/scene.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

struct Case {
  const char* name;
  vec3 offset;
  float scale;
  bool moving;
};

class SpawnOffset : public ::testing::TestWithParam<Case> {};

SceneInput one_object(const Case& c, const ShapeDesc& shape) {
  SceneInput in;
  in.camera = camera_looking(c.offset + vec3(0, 0, 5) * c.scale, c.offset, 40.f);
  in.materials = {DiffuseParams{}};
  ObjectDesc o;
  o.shape = shape;
  if (c.moving) {
    o.velocity = vec3(0.3f, 0.1f, 0.f) * c.scale;
    o.acceleration = vec3(0.f, -0.5f, 0.2f) * c.scale;
    in.camera.shutter_open = 0.f;
    in.camera.shutter_close = 1.f;
  }
  in.objects = {o};
  return in;
}

// Fires rays at the object from random directions; from each hit, spawns rays to the side of
// the incoming ray and counts any that hit the object again (none may: it is convex or flat).
// For spheres, also spawns rays into the surface and checks they reach the far side.
void check_no_self_hits(const SceneInput& in, float scale, const vec3& center, bool sphere) {
  const auto scene = Scene::build(in);
  const Scene& s = *scene;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
  int hits = 0, self_hits = 0, lost_exits = 0;
  for (int i = 0; i < 4000; ++i) {
    const float time = u01(rng);
    const vec3 dir_in = -square_to_uniform_sphere({u01(rng), u01(rng)});
    // Aim at a random point near the object so grazing hits are common.
    const vec3 target = center + (vec3(u01(rng), u01(rng), u01(rng)) - 0.5f) * 1.2f * scale;
    Ray ray{target - dir_in * 10.f * scale, dir_in, time};
    SurfaceHit hit;
    if (!s.intersect(ray, &hit)) continue;
    ++hits;
    const vec3 n = glm::dot(hit.ng, ray.direction) < 0.f ? hit.ng : -hit.ng;
    const Frame frame(n);
    for (int k = 0; k < 4; ++k) {
      vec3 w = frame.to_world(square_to_cosine_hemisphere({u01(rng), u01(rng)}));
      if (k == 0) w = glm::normalize(frame.to_world(vec3(1.f, 0.f, 1e-4f)));  // grazing
      Ray out{offset_ray_origin(hit.p, hit.p_error, hit.ng, w), w, time};
      SurfaceHit again;
      if (s.intersect(out, &again)) ++self_hits;
    }
    if (sphere && glm::dot(ray.direction, hit.ng) < 0.f) {
      // Into the sphere: must hit it again on the far side, at the chord length.
      const vec3 w = frame.to_world(-square_to_cosine_hemisphere({u01(rng), u01(rng)}));
      Ray in_ray{offset_ray_origin(hit.p, hit.p_error, hit.ng, w), w, time};
      SurfaceHit far;
      const float chord = 2.f * std::get<SphereDesc>(in.objects[0].shape).radius * std::abs(glm::dot(w, hit.ng));
      if (!s.intersect(in_ray, &far)) {
        ++lost_exits;
        continue;
      }
      // Far from the origin float positions carry absolute error; allow what the bounds say.
      const float tol = 1e-3f * chord + 4.f * (max_component(hit.p_error) + max_component(far.p_error));
      if (std::abs(far.t - chord) > tol) ++lost_exits;
    }
  }
  EXPECT_GT(hits, 500);
  EXPECT_EQ(self_hits, 0) << "of " << hits * 4 << " spawned rays";
  EXPECT_EQ(lost_exits, 0);
}

TEST_P(SpawnOffset, Sphere) {
  const Case c = GetParam();
  check_no_self_hits(one_object(c, SphereDesc{c.offset, 0.5f * c.scale}), c.scale, c.offset, true);
}

TEST_P(SpawnOffset, Quad) {
  const Case c = GetParam();
  const vec3 o = c.offset - vec3(0.5f, 0.3f, 0.2f) * c.scale;
  check_no_self_hits(one_object(c, QuadDesc{o, vec3(1.f, 0.2f, 0.f) * c.scale, vec3(0.f, 0.6f, 0.8f) * c.scale}),
                     c.scale, c.offset, false);
}

TEST_P(SpawnOffset, Triangle) {
  const Case c = GetParam();
  MeshDesc m;
  m.positions = {c.offset + vec3(-0.5f, -0.4f, 0.1f) * c.scale, c.offset + vec3(0.6f, -0.3f, -0.2f) * c.scale,
                 c.offset + vec3(0.f, 0.5f, 0.3f) * c.scale};
  m.indices = {0, 1, 2};
  check_no_self_hits(one_object(c, m), c.scale, c.offset, false);
}

INSTANTIATE_TEST_SUITE_P(
    Scales, SpawnOffset,
    ::testing::Values(Case{"unit", vec3(0.f), 1.f, false}, Case{"small", vec3(0.f), 1e-3f, false},
                      Case{"large", vec3(0.f), 1e3f, false},
                      Case{"far1e5", vec3(1e5f, -2e5f, 1e5f), 1.f, false},
                      Case{"far1e6", vec3(1e6f, 1e6f, -1e6f), 1.f, false},
                      Case{"moving", vec3(0.f), 1.f, true},
                      Case{"moving_far", vec3(1e5f, 0.f, 0.f), 1.f, true}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace penumbra::test

namespace penumbra::test {
namespace {
TEST(NextFloat, MatchesNextafter) {
  for (float v : {0.f, -0.f, 1.f, -1.f, 1e-40f, -1e-40f, 3.5e6f, -2.25e-3f, 1e38f, -1e38f}) {
    EXPECT_EQ(next_float_up(v), std::nextafter(v, INFINITY)) << v;
    EXPECT_EQ(next_float_down(v), std::nextafter(v, -INFINITY)) << v;
  }
}
}  // namespace
}  // namespace penumbra::test
