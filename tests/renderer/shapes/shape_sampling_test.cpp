// Each shape's sampling against analytic solid angles: for any sampling strategy, the mean of
// 1/pdf over the samples estimates the solid angle the shape covers as seen from the reference
// point (for a flat shape, counted once per side that faces it), and sample() and pdf() agree.
#include <gtest/gtest.h>

#include <random>

#include "renderer/shapes/quad.h"
#include "renderer/shapes/sphere.h"
#include "renderer/shapes/triangle_mesh.h"

namespace penumbra::test {
namespace {

// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom & Strackee 1983).
double triangle_solid_angle(dvec3 a, dvec3 b, dvec3 c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = std::abs(glm::dot(a, glm::cross(b, c)));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  double omega = 2.0 * std::atan2(num, den);
  if (omega < 0.0) omega += 2.0 * M_PI;
  return omega;
}

struct Estimate {
  double mean_inverse_pdf = 0.0, stderr_ = 0.0;
  int failed = 0, pdf_mismatch = 0, off_surface = 0;
};

template <typename OnSurface>
Estimate estimate(const Shape& shape, const vec3& ref, float time, OnSurface on_surface, int n = 200000) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
  Estimate e;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    ShapeSample s;
    if (!shape.sample(ref, time, {u01(rng), u01(rng)}, &s) || !(s.pdf > 0.f)) {
      ++e.failed;
      continue;
    }
    const double inv = 1.0 / s.pdf;
    sum += inv;
    sum2 += inv * inv;
    const float again = shape.pdf(ref, s.p, s.n, time);
    if (std::abs(again - s.pdf) > 1e-3f * s.pdf) ++e.pdf_mismatch;
    if (!on_surface(s.p)) ++e.off_surface;
  }
  e.mean_inverse_pdf = sum / n;
  e.stderr_ = std::sqrt(std::max(0.0, sum2 / n - e.mean_inverse_pdf * e.mean_inverse_pdf) / n);
  return e;
}

ShapeContext still() { return ShapeContext{}; }

TEST(ShapeSampling, SphereSeenFromOutsideCoversItsCone) {
  const Sphere sphere(SphereDesc{vec3(0.3f, -0.2f, 0.1f), 0.7f}, still());
  const vec3 ref(2.f, 1.f, -1.5f);
  const double d = glm::length(dvec3(ref) - dvec3(0.3, -0.2, 0.1));
  const double expected = 2.0 * M_PI * (1.0 - std::sqrt(1.0 - 0.49 / (d * d)));
  const Estimate e = estimate(sphere, ref, 0.f, [](const vec3& p) {
    return std::abs(glm::length(p - vec3(0.3f, -0.2f, 0.1f)) - 0.7f) < 1e-5f;
  });
  EXPECT_EQ(e.failed, 0);
  EXPECT_EQ(e.pdf_mismatch, 0);
  EXPECT_EQ(e.off_surface, 0);
  EXPECT_NEAR(e.mean_inverse_pdf, expected, 1e-4 * expected);  // solid-angle sampling: pdf constant
  EXPECT_FLOAT_EQ(sphere.area(), 4.f * kPi * 0.49f);
}

TEST(ShapeSampling, SphereSeenFromInsideCoversEveryDirection) {
  const Sphere sphere(SphereDesc{vec3(0.f), 1.f}, still());
  const Estimate e = estimate(sphere, vec3(0.2f, 0.3f, -0.1f), 0.f,
                              [](const vec3& p) { return std::abs(glm::length(p) - 1.f) < 1e-5f; });
  EXPECT_EQ(e.pdf_mismatch, 0);
  EXPECT_NEAR(e.mean_inverse_pdf, 4.0 * M_PI, 4.0 * e.stderr_ + 1e-3);
}

TEST(ShapeSampling, QuadCoversItsTwoTriangles) {
  const QuadDesc q{vec3(-0.5f, 1.f, -0.3f), vec3(1.2f, 0.f, 0.2f), vec3(0.1f, 0.3f, 0.9f)};
  const Quad quad(q, still());
  const vec3 ref(0.2f, -0.4f, 0.1f);
  const dvec3 o = dvec3(q.origin) - dvec3(ref), u(q.u), v(q.v);
  const double expected = triangle_solid_angle(o, o + u, o + u + v) + triangle_solid_angle(o, o + u + v, o + v);
  const vec3 n = glm::normalize(glm::cross(q.u, q.v));
  const Estimate e = estimate(quad, ref, 0.f, [&](const vec3& p) {
    return std::abs(glm::dot(p - q.origin, n)) < 1e-5f;
  });
  EXPECT_EQ(e.failed, 0);
  EXPECT_EQ(e.pdf_mismatch, 0);
  EXPECT_EQ(e.off_surface, 0);
  EXPECT_NEAR(e.mean_inverse_pdf, expected, 4.0 * e.stderr_);
  EXPECT_FLOAT_EQ(quad.area(), glm::length(glm::cross(q.u, q.v)));
}

// Two triangles of very different areas, not coplanar: the triangle choice by area (the CDF) and
// the point inside each are both checked by the solid angle.
TEST(ShapeSampling, MeshPicksTrianglesByArea) {
  MeshDesc m;
  m.positions = {vec3(-1, 0, -1), vec3(1, 0, -1), vec3(1, 0, 1), vec3(1, 0.2f, 1.1f), vec3(1.3f, 0.4f, 1.2f)};
  m.indices = {0, 1, 2, 2, 3, 4};
  ShapeContext ctx;
  ctx.emissive = true;
  const TriangleMesh mesh(m, ctx);
  const vec3 ref(0.1f, 1.5f, 0.2f);
  const auto rel = [&](int i) { return dvec3(m.positions[i]) - dvec3(ref); };
  const double expected = triangle_solid_angle(rel(0), rel(1), rel(2)) + triangle_solid_angle(rel(2), rel(3), rel(4));
  const Estimate e = estimate(mesh, ref, 0.f, [](const vec3&) { return true; });
  EXPECT_EQ(e.failed, 0);
  EXPECT_EQ(e.pdf_mismatch, 0);
  EXPECT_NEAR(e.mean_inverse_pdf, expected, 4.0 * e.stderr_);
}

// A moving shape samples points where it is at the given time.
TEST(ShapeSampling, MovingShapesSampleWhereTheyAreAtThatTime) {
  ShapeContext ctx;
  ctx.motion = ShapeMotion{Motion{vec3(1.f, 0.f, 0.f), vec3(0.f, 2.f, 0.f)}, 0.f, 1.f};
  ctx.emissive = true;
  const Sphere sphere(SphereDesc{vec3(0.f), 0.5f}, ctx);
  const Quad quad(QuadDesc{vec3(0.f), vec3(1, 0, 0), vec3(0, 0, 1)}, ctx);
  for (float t : {0.f, 0.5f, 1.f}) {
    const vec3 shift(t, t * t, 0.f);  // v t + a t^2 / 2
    const Estimate es = estimate(sphere, vec3(0, 5, 0), t, [&](const vec3& p) {
      return std::abs(glm::length(p - shift) - 0.5f) < 1e-4f;
    }, 2000);
    EXPECT_EQ(es.off_surface, 0) << "time " << t;
    // Triangles move as Embree interpolates them: linearly between time steps, which for this
    // acceleration and a camera at the origin are dense enough to be within 1e-3 of the path.
    const Estimate eq = estimate(quad, vec3(0, 5, 0), t, [&](const vec3& p) {
      return std::abs(p.y - shift.y) < 1e-3f;
    }, 2000);
    EXPECT_EQ(eq.off_surface, 0) << "time " << t;
  }
}

TEST(ShapeBounds, ContainTheShapeOverTheShutter) {
  ShapeContext ctx;
  ctx.motion = ShapeMotion{Motion{vec3(1.f, 0.f, 0.f), vec3(0.f, -4.f, 0.f)}, 0.f, 1.f};
  const Sphere sphere(SphereDesc{vec3(0.f), 0.5f}, ctx);
  const Bounds3 b = sphere.bounds();
  // x from -0.5 to 1.5; y: displacement -2 t^2 from 0 to -2, so -2.5 .. 0.5.
  EXPECT_FLOAT_EQ(b.lo.x, -0.5f);
  EXPECT_FLOAT_EQ(b.hi.x, 1.5f);
  EXPECT_FLOAT_EQ(b.lo.y, -2.5f);
  EXPECT_FLOAT_EQ(b.hi.y, 0.5f);
  ctx.motion = ShapeMotion{};
  ctx.offset = vec3(0.f, 0.f, 3.f);
  const TriangleMesh mesh(MeshDesc{{vec3(0.f), vec3(1, 0, 0), vec3(0, 1, 0)}, {0, 1, 2}, {}}, ctx);
  EXPECT_EQ(mesh.bounds().lo, vec3(0.f, 0.f, 3.f));
  EXPECT_EQ(mesh.bounds().hi, vec3(1.f, 1.f, 3.f));
  EXPECT_FLOAT_EQ(mesh.area(), 0.5f);
}

}  // namespace
}  // namespace penumbra::test
