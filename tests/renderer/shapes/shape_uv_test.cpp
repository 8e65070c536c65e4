// Surface coordinates of hits: a quad's (s, t), a sphere's Mitsuba 3 mapping, a mesh's
// interpolated uvs (barycentrics without them).
#include <gtest/gtest.h>

#include "renderer/embree/device.h"
#include "renderer/embree/ray_access.h"
#include "renderer/shapes/make_shape.h"
#include "renderer/shapes/sphere.h"

namespace penumbra::test {
namespace {

// Shapes compute their uv only when the scene reads it (ShapeContext::need_uv, set by textured
// materials): the shape is built with it, put alone in an Embree scene and hit from +z.
SurfaceHit hit_from_above(const ShapeDesc& desc, const vec3& target, bool need_uv = true) {
  ShapeContext ctx;
  ctx.need_uv = need_uv;
  const auto shape = make_shape(desc, ctx);
  EmbreeScene scene(rtcNewScene(embree_device()));
  EmbreeGeometry geom = shape->make_geometry(embree_device());
  rtcAttachGeometry(scene.get(), geom.get());
  rtcCommitScene(scene.get());
  const Ray ray{target + vec3(0.f, 0.f, 5.f), vec3(0.f, 0.f, -1.f), 0.f};
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh = embree_ray_hit(ray);
  rtcIntersect1(scene.get(), &context, &rh);
  SurfaceHit hit;
  EXPECT_NE(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID);
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
    shape->hit_geometry(ray, rh.ray.tfar, rh.hit.primID, vec2(rh.hit.u, rh.hit.v), &hit);
  return hit;
}

TEST(ShapeUv, QuadUvIsSAndT) {
  const QuadDesc q{vec3(1.f, 2.f, 0.f), vec3(2.f, 0.f, 0.f), vec3(0.5f, 1.f, 0.f)};
  // Points in both triangles of Embree's split of the quad (s + t < 1 and > 1) and on its
  // diagonal: the hit point rebuilt from the hit's triangle is the point aimed at.
  for (const vec2 st : {vec2(0.25f, 0.75f), vec2(0.8f, 0.1f), vec2(0.5f, 0.5f), vec2(0.9f, 0.7f),
                        vec2(0.3f, 0.95f)}) {
    const vec3 target = q.origin + st.x * q.u + st.y * q.v;
    const SurfaceHit h = hit_from_above(q, target);
    EXPECT_NEAR(h.uv.x, st.x, 1e-5f);
    EXPECT_NEAR(h.uv.y, st.y, 1e-5f);
    EXPECT_NEAR(glm::length(h.p - target), 0.f, 1e-5f);
  }
}

// The sphere computes its uv only when the scene reads it (ShapeContext::need_uv).
SurfaceHit sphere_hit_from_above(const vec3& target) {
  ShapeContext ctx;
  ctx.need_uv = true;
  const Sphere sphere(SphereDesc{vec3(0.f), 1.f}, ctx);
  const Ray ray{target + vec3(0.f, 0.f, 5.f), vec3(0.f, 0.f, -1.f), 0.f};
  const float t = intersect_sphere(vec3(0.f), 1.f, ray.origin, ray.direction, kInfinity);
  EXPECT_GT(t, 0.f);
  SurfaceHit hit;
  sphere.hit_geometry(ray, t, 0, vec2(0.f), &hit);
  return hit;
}

TEST(ShapeUv, SphereUvFollowsMitsuba) {
  // From +z straight down onto the pole: theta = 0. Off the pole towards +y: phi = pi/2.
  const SurfaceHit pole = sphere_hit_from_above(vec3(0.f));
  EXPECT_NEAR(pole.uv.y, 0.f, 1e-3f);
  const float s = std::sin(0.5f);
  const SurfaceHit side = sphere_hit_from_above(vec3(0.f, s, 0.f));
  EXPECT_NEAR(side.uv.x, 0.25f, 1e-5f);
  EXPECT_NEAR(side.uv.y, 0.5f / kPi, 1e-4f);
  const SurfaceHit neg = sphere_hit_from_above(vec3(0.f, -s, 0.f));
  EXPECT_NEAR(neg.uv.x, 0.75f, 1e-5f);  // phi wrapped into [0, 2 pi)
}

TEST(ShapeUv, MeshInterpolatesItsUvsOrGivesBarycentrics) {
  MeshDesc m{{vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(0.f, 1.f, 0.f)}, {0, 1, 2}, {}, {}};
  const SurfaceHit bary = hit_from_above(m, vec3(0.2f, 0.3f, 0.f));
  EXPECT_NEAR(bary.uv.x, 0.2f, 1e-5f);
  EXPECT_NEAR(bary.uv.y, 0.3f, 1e-5f);
  m.uvs = {vec2(0.5f, 0.5f), vec2(1.f, 0.5f), vec2(0.5f, 0.f)};
  const SurfaceHit mapped = hit_from_above(m, vec3(0.2f, 0.3f, 0.f));
  EXPECT_NEAR(mapped.uv.x, 0.5f + 0.5f * 0.2f, 1e-5f);
  EXPECT_NEAR(mapped.uv.y, 0.5f - 0.5f * 0.3f, 1e-5f);
}

// Without a reader of uv the mesh skips the interpolation (a hot path): uv keeps its default.
TEST(ShapeUv, MeshSkipsUvWhenNothingReadsIt) {
  const MeshDesc m{{vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(0.f, 1.f, 0.f)}, {0, 1, 2}, {}, {}};
  const SurfaceHit h = hit_from_above(m, vec3(0.2f, 0.3f, 0.f), /*need_uv=*/false);
  EXPECT_EQ(h.uv, vec2(0.f));
  EXPECT_NEAR(h.p.x, 0.2f, 1e-5f);
}

}  // namespace
}  // namespace penumbra::test
