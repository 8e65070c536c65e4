// dp/du and dp/dv of each shape's uv parametrisation (the tangent frame normal maps use), and
// the uv of points sampled on emitters (textured emission), against values worked out by hand
// or by finite differences of the shape's own mapping.
#include <gtest/gtest.h>

#include "renderer/shapes/make_shape.h"
#include "renderer/shapes/sphere.h"
#include "renderer/shapes/triangle_mesh.h"

namespace penumbra::test {
namespace {

void expect_vec_near(const vec3& a, const vec3& b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// A hit on `shape` at barycentrics / parameters `bary` of primitive `prim`, rebuilt by the shape.
SurfaceHit hit_at(const Shape& shape, const vec3& p, uint32_t prim, const vec2& bary) {
  SurfaceHit hit;
  hit.primitive = prim;
  const vec3 origin = p + vec3(0.f, 0.f, 3.f);
  shape.hit_geometry(Ray{origin, vec3(0.f, 0.f, -1.f), 0.f}, 3.f, prim, bary, &hit);
  shape.surface_derivatives(0.f, &hit);
  return hit;
}

TEST(SurfaceDerivatives, QuadIsItsEdgeVectors) {
  const QuadDesc q{vec3(1.f, 2.f, 0.f), vec3(2.f, 0.5f, 0.f), vec3(-0.5f, 1.f, 0.f)};
  const auto quad = make_shape(q, ShapeContext{});
  for (uint32_t prim : {0u, 1u}) {
    const SurfaceHit h = hit_at(*quad, q.origin, prim, vec2(0.2f, 0.3f));
    expect_vec_near(h.dpdu, q.u, 1e-5f);
    expect_vec_near(h.dpdv, q.v, 1e-5f);
  }
}

TEST(SurfaceDerivatives, MeshWithoutUvsFollowsItsBarycentrics) {
  // uv = (b1, b2): p = p0 + u (p1 - p0) + v (p2 - p0).
  const MeshDesc m{{vec3(0.f), vec3(2.f, 0.f, 0.f), vec3(0.5f, 1.f, 0.f)}, {0, 1, 2}, {}, {}};
  const TriangleMesh mesh(m, ShapeContext{});
  const SurfaceHit h = hit_at(mesh, vec3(0.5f, 0.3f, 0.f), 0, vec2(0.2f, 0.3f));
  expect_vec_near(h.dpdu, vec3(2.f, 0.f, 0.f), 1e-6f);
  expect_vec_near(h.dpdv, vec3(0.5f, 1.f, 0.f), 1e-6f);
}

TEST(SurfaceDerivatives, MeshWithUvsSolvesTheParametrisation) {
  // uvs stretched 2x along u and flipped along v: dp/du = (0.5, 0, 0), dp/dv = (0, -1, 0).
  const MeshDesc m{{vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(0.f, 1.f, 0.f)},
                   {0, 1, 2},
                   {},
                   {vec2(0.f, 1.f), vec2(2.f, 1.f), vec2(0.f, 0.f)}};
  const TriangleMesh mesh(m, ShapeContext{});
  const SurfaceHit h = hit_at(mesh, vec3(0.25f, 0.25f, 0.f), 0, vec2(0.25f, 0.25f));
  expect_vec_near(h.dpdu, vec3(0.5f, 0.f, 0.f), 1e-6f);
  expect_vec_near(h.dpdv, vec3(0.f, -1.f, 0.f), 1e-6f);
  // Degenerate uvs (all equal): still a tangent frame of the normal.
  MeshDesc flat = m;
  flat.uvs.assign(3, vec2(0.5f));
  const SurfaceHit d =
      hit_at(TriangleMesh(flat, ShapeContext{}), vec3(0.25f, 0.25f, 0.f), 0, vec2(0.25f));
  EXPECT_NEAR(glm::dot(d.dpdu, d.ng), 0.f, 1e-6f);
  EXPECT_NEAR(glm::length(glm::cross(d.dpdu, d.dpdv)), 1.f, 1e-5f);
}

TEST(SurfaceDerivatives, SphereMatchesFiniteDifferencesOfItsMapping) {
  const vec3 c(0.5f, -1.f, 2.f);
  const float r = 1.5f;
  const Sphere sphere(SphereDesc{c, r}, ShapeContext{});
  // The point of the sphere at (u, v) under Mitsuba's mapping.
  auto point = [&](double u, double v) {
    const double phi = 2 * M_PI * u, theta = M_PI * v;
    return dvec3(c) + double(r) * dvec3(std::sin(theta) * std::cos(phi),
                                        std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  for (const vec2 uv : {vec2(0.1f, 0.3f), vec2(0.6f, 0.8f), vec2(0.95f, 0.5f)}) {
    const vec3 p = vec3(point(uv.x, uv.y));
    SurfaceHit hit;
    sphere_hit_geometry(c, r, p, &hit);
    hit.uv = sphere_uv(hit.ng);
    EXPECT_NEAR(hit.uv.x, uv.x, 1e-5f);
    EXPECT_NEAR(hit.uv.y, uv.y, 1e-5f);
    sphere.surface_derivatives(0.f, &hit);
    const double h = 1e-5;
    const vec3 du = vec3((point(uv.x + h, uv.y) - point(uv.x - h, uv.y)) / (2 * h));
    const vec3 dv = vec3((point(uv.x, uv.y + h) - point(uv.x, uv.y - h)) / (2 * h));
    expect_vec_near(hit.dpdu, du, 1e-4f * glm::length(du));
    expect_vec_near(hit.dpdv, dv, 1e-4f * glm::length(dv));
  }
}

TEST(ShapeSampleUv, SampledPointsCarryTheUvAHitThereWouldHave) {
  ShapeContext ctx;
  ctx.emissive = true;
  ctx.sample_uv = true;
  const vec3 ref(0.3f, 0.2f, 5.f);
  const vec2 us[] = {vec2(0.1f, 0.2f), vec2(0.7f, 0.4f), vec2(0.45f, 0.9f)};
  // Quad: the point origin + s u + t v has uv (s, t), and sampling places it at s, t = u.
  const QuadDesc q{vec3(0.f), vec3(2.f, 0.f, 0.f), vec3(0.f, 1.f, 0.f)};
  const auto quad = make_shape(q, ctx);
  // Mesh on the unit right triangle: barycentrics (b1, b2) = (x, y) of the point.
  const MeshDesc m{{vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(0.f, 1.f, 0.f)},
                   {0, 1, 2},
                   {},
                   {vec2(0.5f, 0.5f), vec2(1.f, 0.5f), vec2(0.5f, 0.f)}};
  const auto mesh = make_shape(m, ctx);
  const auto sphere = make_shape(SphereDesc{vec3(0.f), 1.f}, ctx);
  for (const vec2 u : us) {
    ShapeSample s;
    ASSERT_TRUE(quad->sample(ref, 0.f, u, &s));
    EXPECT_NEAR(s.uv.x, s.p.x / 2.f, 1e-6f);
    EXPECT_NEAR(s.uv.y, s.p.y, 1e-6f);
    ASSERT_TRUE(mesh->sample(ref, 0.f, u, &s));
    const float b0 = 1.f - s.p.x - s.p.y, b1 = s.p.x, b2 = s.p.y;
    const vec2 expected = b0 * m.uvs[0] + b1 * m.uvs[1] + b2 * m.uvs[2];
    EXPECT_NEAR(s.uv.x, expected.x, 1e-6f);
    EXPECT_NEAR(s.uv.y, expected.y, 1e-6f);
    ASSERT_TRUE(sphere->sample(ref, 0.f, u, &s));
    EXPECT_EQ(s.uv, sphere_uv(s.n));
  }
}

}  // namespace
}  // namespace penumbra::test
