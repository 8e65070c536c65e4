// A static quad's own ray test (shapes/parallelogram.h): where it hits and what it reports, that
// a ray spawned from one of its hits never meets it again, that two quads sharing an edge leave
// no crack, and that its packets of 4, 8 and 16 rays give every lane the single ray's bits, with
// the quads' overlapping edges and with a mesh face pair's exact ones.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "renderer/core/ray.h"
#include "renderer/embree/ray_access.h"
#include "renderer/shapes/parallelogram.h"
#include "renderer/shapes/quad.h"
#include "tests/renderer/shapes/packet_test_util.h"

namespace penumbra::test {
namespace {

constexpr unsigned kPrim = 0, kGeom = 5, kInst = 3;

// One ray through the N = 1 callbacks: the hit's t and (s, t), or t < 0 if none.
struct OneHit {
  float t = -1.f;
  vec2 st{0.f};
  unsigned geom = RTC_INVALID_GEOMETRY_ID;
};

OneHit intersect_one(const Parallelogram& q, const vec3& o, const vec3& d, float tnear = 0.f,
                     float tfar = kInfinity) {
  RTCRayHit rh = embree_ray_hit(Ray{o, d, 0.f, tfar});
  rh.ray.tnear = tnear;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  int valid = -1;
  const RTCIntersectFunctionNArguments args{&valid, const_cast<Parallelogram*>(&q), kPrim, &ctx,
                                            reinterpret_cast<RTCRayHitN*>(&rh), 1, kGeom};
  parallelogram_intersect_fn(&args);
  OneHit h;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
  h.t = rh.ray.tfar;
  h.st = vec2(rh.hit.u, rh.hit.v);
  h.geom = rh.hit.geomID;
  return h;
}

bool occluded_one(const Parallelogram& q, const vec3& o, const vec3& d, float tfar) {
  RTCRay ray = embree_ray_hit(Ray{o, d, 0.f, tfar}).ray;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  int valid = -1;
  const RTCOccludedFunctionNArguments args{&valid, const_cast<Parallelogram*>(&q), kPrim, &ctx,
                                           reinterpret_cast<RTCRayN*>(&ray), 1, kGeom};
  parallelogram_occluded_fn(&args);
  return ray.tfar == -kInfinity;
}

TEST(Parallelogram, HitsWhereThePlaneMeetsTheRayInsideTheEdges) {
  // A sheared, tilted parallelogram away from the origin.
  const QuadDesc desc{vec3(1.f, -2.f, 3.f), vec3(2.f, 0.5f, 0.f), vec3(0.3f, 0.f, -1.5f)};
  const Parallelogram q(desc);
  const vec3 n = glm::normalize(glm::cross(desc.u, desc.v));
  for (const vec2 st : {vec2(0.5f), vec2(0.1f, 0.9f), vec2(0.99f, 0.01f), vec2(0.f, 0.5f)}) {
    const vec3 p = desc.origin + st.x * desc.u + st.y * desc.v;
    for (const float side : {1.f, -1.f}) {  // from the front and from the back
      const vec3 o = p + side * 3.f * n + vec3(0.2f, 0.1f, -0.3f);
      const vec3 d = glm::normalize(p - o);
      const float want = glm::length(p - o);
      const OneHit h = intersect_one(q, o, d);
      ASSERT_EQ(h.geom, kGeom) << st.x << "," << st.y << " side " << side;
      EXPECT_NEAR(h.t, want, 1e-5f * want);
      EXPECT_NEAR(h.st.x, st.x, 1e-5f);
      EXPECT_NEAR(h.st.y, st.y, 1e-5f);
      EXPECT_TRUE(occluded_one(q, o, d, kInfinity));
      // Not before tnear, not at or beyond tfar.
      EXPECT_EQ(intersect_one(q, o, d, 0.f, 0.99f * want).geom, RTC_INVALID_GEOMETRY_ID);
      EXPECT_FALSE(occluded_one(q, o, d, 0.99f * want));
      EXPECT_EQ(intersect_one(q, o, d, 1.01f * want).geom, RTC_INVALID_GEOMETRY_ID);
      // Pointing away: behind the origin is no hit.
      EXPECT_EQ(intersect_one(q, o, -d).geom, RTC_INVALID_GEOMETRY_ID);
    }
  }
  // Outside the edges by more than the tolerance: a miss; within it: a hit.
  for (const vec2 st : {vec2(-1e-3f, 0.5f), vec2(0.5f, 1.001f), vec2(1.5f, 1.5f), vec2(-0.2f)}) {
    const vec3 p = desc.origin + st.x * desc.u + st.y * desc.v;
    EXPECT_EQ(intersect_one(q, p + n, -n).geom, RTC_INVALID_GEOMETRY_ID) << st.x << "," << st.y;
  }
  for (const vec2 st : {vec2(-2e-6f, 0.5f), vec2(0.5f, 1.f + 2e-6f)}) {
    const vec3 p = desc.origin + st.x * desc.u + st.y * desc.v;
    EXPECT_EQ(intersect_one(q, p + n, -n).geom, kGeom) << st.x << "," << st.y;
  }
  // A ray in the plane, and a degenerate parallelogram, meet nothing.
  EXPECT_EQ(intersect_one(q, desc.origin - desc.u, glm::normalize(desc.u)).geom,
            RTC_INVALID_GEOMETRY_ID);
  const Parallelogram flat(QuadDesc{vec3(0.f), vec3(1.f, 0.f, 0.f), vec3(2.f, 0.f, 0.f)});
  EXPECT_EQ(intersect_one(flat, vec3(0.5f, 1.f, 0.f), vec3(0.f, -1.f, 0.f)).geom,
            RTC_INVALID_GEOMETRY_ID);
}

// A ray spawned from a hit point (core/ray.h's offset beyond the point's error bound), in any
// direction on either side, never meets the quad it leaves, however the quad is tilted, scaled
// or placed: the sign of t is decided in double (a float test of the same formula re-hits).
TEST(Parallelogram, SpawnedRaysNeverMeetTheirOwnQuad) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0.f, 1.f), sym(-1.f, 1.f);
  auto unit = [&] {
    for (;;) {
      const vec3 v(sym(rng), sym(rng), sym(rng));
      if (glm::dot(v, v) > 1e-3f && glm::dot(v, v) <= 1.f) return glm::normalize(v);
    }
  };
  int rehits = 0, tested = 0;
  for (const float scale : {1e-3f, 1.f, 1e3f}) {
    for (int k = 0; k < 40; ++k) {
      const QuadDesc desc{unit() * (scale * 100.f * u01(rng)), unit() * scale * (0.1f + u01(rng)),
                          unit() * scale * (0.1f + u01(rng))};
      if (glm::length(glm::cross(desc.u, desc.v)) < 1e-2f * scale * scale) continue;
      const Quad quad(desc, ShapeContext{});
      ASSERT_TRUE(quad.parallelogram());
      const Parallelogram q(desc);
      for (int i = 0; i < 2000; ++i) {
        // A camera-like ray to a random point of the quad, its hit rebuilt as the renderer does.
        const vec3 target = desc.origin + u01(rng) * desc.u + u01(rng) * desc.v;
        const vec3 o = target + unit() * scale * (1.f + 50.f * u01(rng));
        const vec3 d = glm::normalize(target - o);
        const OneHit h = intersect_one(q, o, d);
        if (h.geom != kGeom) continue;
        SurfaceHit hit;
        quad.hit_geometry(Ray{o, d, 0.f, kInfinity}, h.t, kPrim, h.st, &hit);
        // Reflected or transmitted alike; a third of them grazing, within about 1e-4 rad of
        // the plane, where the sign of d . n decides as much as that of the origin's distance.
        vec3 w = unit();
        if (i % 3 == 0)
          w = glm::normalize(glm::cross(hit.ng, w) + sym(rng) * 1e-4f * hit.ng);
        const vec3 spawned = offset_ray_origin(hit.p, hit.p_error, hit.ng, w);
        ++tested;
        if (intersect_one(q, spawned, w).geom == kGeom || occluded_one(q, spawned, w, kInfinity))
          ++rehits;
      }
    }
  }
  EXPECT_GT(tested, 100000);
  EXPECT_EQ(rehits, 0) << "of " << tested;
}

// Rays from float points next to the plane of a large quad whose corner is far from them
// (TriangleMesh's exact-t case, tests/renderer/scene/exact_t_check_test.cpp): a float plane test
// misjudges the sign of their t by the corner's rounding, ~1000 eps here; the double one reports
// a hit exactly when the exact t of the float ray is positive.
TEST(Parallelogram, SignOfTIsExactForOriginsAtThePlane) {
  const QuadDesc desc{vec3(-1000.f, -1000.f, 300.f), vec3(2000.f, 100.f, -250.f),
                      vec3(150.f, 2000.f, -400.f)};
  const Parallelogram q(desc);
  using ld = long double;
  const ld ux = desc.u.x, uy = desc.u.y, uz = desc.u.z, vx = desc.v.x, vy = desc.v.y, vz = desc.v.z;
  const ld nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int wrong = 0, ahead = 0, behind = 0;
  for (int i = 0; i < 20000; ++i) {
    // The plane's point above (x, y) near the world origin, rounded to float.
    const double x = 2 * u01(rng) - 1, y = 2 * u01(rng) - 1;
    const dvec3 o0(desc.origin), u(desc.u), v(desc.v);
    const double det = u.x * v.y - v.x * u.y;
    const double s = ((x - o0.x) * v.y - v.x * (y - o0.y)) / det;
    const double t = (u.x * (y - o0.y) - (x - o0.x) * u.y) / det;
    const vec3 o(o0 + s * u + t * v);
    const double z = 2 * u01(rng) - 1, phi = 2 * M_PI * u01(rng), r = std::sqrt(1 - z * z);
    const vec3 d(dvec3(r * std::cos(phi), r * std::sin(phi), z));
    const ld num = nx * (ld(desc.origin.x) - ld(o.x)) + ny * (ld(desc.origin.y) - ld(o.y)) +
                   nz * (ld(desc.origin.z) - ld(o.z));
    const ld den = nx * ld(d.x) + ny * ld(d.y) + nz * ld(d.z);
    if (num == 0 || den == 0) continue;
    const bool exact_ahead = (num > 0) == (den > 0);
    (exact_ahead ? ahead : behind)++;
    if ((intersect_one(q, o, d).geom == kGeom) != exact_ahead) ++wrong;
  }
  EXPECT_GT(ahead, 5000);
  EXPECT_GT(behind, 5000);
  EXPECT_EQ(wrong, 0);
}

// Two quads sharing an edge (a fold of a closed box): rays aimed exactly at points of the shared
// edge hit one of them.
TEST(Parallelogram, SharedEdgesLeaveNoCrack) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  int cracks = 0;
  for (const float scale : {1e-3f, 1.f, 1e3f}) {
    const vec3 a = vec3(0.3f, -0.7f, 0.2f) * scale;
    const vec3 edge = vec3(0.9f, 0.4f, -0.1f) * scale, side1 = vec3(0.1f, 0.2f, 1.3f) * scale,
               side2 = vec3(-0.2f, 1.1f, 0.3f) * scale;
    // Quad 1 ends at the edge (its v runs up to it), quad 2 starts there.
    const Parallelogram q1(QuadDesc{a - side1, edge, side1}), q2(QuadDesc{a, edge, side2});
    const vec3 inside = a + 0.3f * side1 - 0.4f * side2 + 0.5f * edge;  // beyond the fold
    for (int i = 0; i < 200000; ++i) {
      const vec3 p = a + u01(rng) * edge;
      const vec3 o = p + (p - inside) * (0.5f + 10.f * u01(rng));
      const vec3 d = glm::normalize(p - o);
      if (intersect_one(q1, o, d).geom != kGeom && intersect_one(q2, o, d).geom != kGeom) ++cracks;
    }
  }
  EXPECT_EQ(cracks, 0);
}

// ---- packets against single rays ----

// Rays at, past, along and from a parallelogram, with tnear and tfar around the hit, invalid
// lanes and garbage (NaNs, infinities) in every field a lane does not set.
Lane random_lane(std::mt19937& rng, const QuadDesc& q) {
  std::uniform_real_distribution<float> u01(0.f, 1.f), sym(-1.f, 1.f);
  auto unit = [&] {
    for (;;) {
      const vec3 v(sym(rng), sym(rng), sym(rng));
      if (glm::dot(v, v) > 1e-3f && glm::dot(v, v) <= 1.f) return glm::normalize(v);
    }
  };
  Lane l;
  for (uint32_t& x : l.f) {
    switch (rng() % 4) {
      case 0: x = bits(std::numeric_limits<float>::quiet_NaN()); break;
      case 1: x = bits(-kInfinity); break;
      default: x = static_cast<uint32_t>(rng());
    }
  }
  l.valid = rng() % 8 != 0;
  const float size = glm::length(q.u) + glm::length(q.v);
  const vec3 n = glm::normalize(glm::cross(q.u, q.v));
  // A point of the plane around the parallelogram, edges included.
  const float s = rng() % 4 == 0 ? float(rng() % 3) * 0.5f : -0.2f + 1.4f * u01(rng);
  const float t = rng() % 4 == 0 ? float(rng() % 3) * 0.5f : -0.2f + 1.4f * u01(rng);
  const vec3 p = q.origin + s * q.u + t * q.v;
  vec3 o, d;
  switch (rng() % 4) {
    case 0:  // anywhere, any direction
      o = p + unit() * size * 3.f * u01(rng);
      d = unit();
      break;
    case 1:  // in the plane, along it
      o = p;
      d = glm::normalize(q.u);
      break;
    case 2:  // from the plane (a spawned ray without its offset)
      o = p;
      d = unit();
      break;
    default:  // aimed at the point
      o = p + unit() * size * (0.5f + 20.f * u01(rng));
      d = glm::normalize(p - o);
      break;
  }
  float tnear = 0.f, tfar = kInfinity;
  const float hit_t = glm::dot(p - o, d);
  switch (rng() % 8) {
    case 0: tnear = hit_t; break;
    case 1: tfar = hit_t; break;
    case 2: tfar = std::nextafter(hit_t, kInfinity); break;
    case 3: tfar = -kInfinity; break;
    case 4: tnear = std::numeric_limits<float>::quiet_NaN(); break;
    default: break;
  }
  if (!l.valid && rng() % 2) return l;
  const float ray[kRayFields] = {o.x, o.y, o.z, tnear, d.x, d.y, d.z, u01(rng), tfar};
  for (int k = 0; k <= kTfar; ++k) l.f[k] = bits(ray[k]);
  l.f[kMask] = 0xFFFFFFFFu;
  return l;
}

template <class RayHitK, class RayK>
void expect_packets_match(const Parallelogram& q, const QuadDesc& desc, int packets,
                          uint32_t seed) {
  constexpr int kN = sizeof(RayK{}.tfar) / 4;
  std::mt19937 rng(seed);
  void* user = const_cast<Parallelogram*>(&q);
  for (int p = 0; p < packets; ++p) {
    std::vector<Lane> lanes;
    for (int i = 0; i < kN; ++i) lanes.push_back(random_lane(rng, desc));
    expect_intersect_lanes_match<RayHitK>(parallelogram_intersect_fn, user, lanes, kPrim, kGeom,
                                          kInst);
    expect_occluded_lanes_match<RayK>(parallelogram_occluded_fn, user, lanes, kPrim, kGeom);
    if (testing::Test::HasFatalFailure()) return;
  }
}

TEST(Parallelogram, PacketLanesMatchSingleRays) {
  for (const QuadDesc& desc :
       {QuadDesc{vec3(-4.f, 0.f, -4.f), vec3(0.f, 0.f, 8.f), vec3(8.f, 0.f, 0.f)},
        QuadDesc{vec3(1.f, -2.f, 3.f), vec3(2.f, 0.5f, 0.f), vec3(0.3f, 0.f, -1.5f)},
        QuadDesc{vec3(300.f, 120.f, -80.f), vec3(1e-2f, 3e-3f, 0.f), vec3(0.f, 2e-3f, 1e-2f)}}) {
    for (const bool exact : {false, true}) {
      // Exact edges (a mesh's face pair), the fourth corner an ulp off origin + u + v.
      Parallelogram q(desc);
      const vec3 far = desc.origin + desc.u + desc.v;
      if (exact)
        q.use_exact_edges(desc.origin, desc.origin + desc.u,
                          vec3(std::nextafter(far.x, kInfinity), far.y, far.z),
                          desc.origin + desc.v);
      expect_packets_match<RTCRayHit16, RTCRay16>(q, desc, 2000, 1);
      expect_packets_match<RTCRayHit8, RTCRay8>(q, desc, 1000, 2);
      expect_packets_match<RTCRayHit4, RTCRay4>(q, desc, 1000, 3);
      if (HasFatalFailure()) return;
    }
  }
}

}  // namespace
}  // namespace penumbra::test
