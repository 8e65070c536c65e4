// The sphere's Embree callbacks on packets of 4, 8 and 16 rays (SIMD lanes) against the same
// callbacks on one ray at a time: every lane's ray and hit fields must be the single ray's to the
// bit, and a lane that is invalid or misses must come back untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "renderer/shapes/sphere.h"
#include "tests/renderer/shapes/packet_test_util.h"

namespace penumbra::test {
namespace {

constexpr unsigned kPrim = 7, kGeom = 5, kInst = 3;

class Rays {
 public:
  explicit Rays(uint32_t seed) : rng_(seed) {}
  float uniform(float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng_); }
  uint32_t garbage() {
    // Random bits, NaNs and infinities among them.
    switch (rng_() % 4) {
      case 0: return bits(std::numeric_limits<float>::quiet_NaN());
      case 1: return bits(-kInfinity);
      default: return static_cast<uint32_t>(rng_());
    }
  }
  vec3 unit() {
    for (;;) {
      const vec3 v(uniform(-1.f, 1.f), uniform(-1.f, 1.f), uniform(-1.f, 1.f));
      const float l2 = glm::dot(v, v);
      if (l2 > 1e-3f && l2 <= 1.f) return glm::normalize(v);
    }
  }

  // A ray towards, past, along or from inside a sphere of centre c (at the ray's time) and
  // radius r, with edge cases of tnear and tfar around its roots.
  Lane lane(const vec3& c, float r, float time) {
    Lane l;
    for (uint32_t& x : l.f) x = garbage();
    l.valid = rng_() % 8 != 0;
    vec3 o, d = unit();
    switch (rng_() % 6) {
      case 0:  // anywhere, any direction
        o = c + uniform(0.f, 6.f * r) * unit();
        break;
      case 1:  // aimed at a point near the sphere
        o = c + uniform(1.5f * r, 40.f * r) * unit();
        d = glm::normalize(c + uniform(0.f, 1.2f * r) * unit() - o);
        break;
      case 2: {  // grazing: through a point of the silhouette, give or take a few ulps
        const vec3 u = glm::normalize(glm::cross(d, unit()));
        const float s = 1.f + static_cast<float>(static_cast<int>(rng_() % 9) - 4) * 6e-8f;
        o = c + (r * s) * u - uniform(0.5f * r, 20.f * r) * d;
        break;
      }
      case 3:  // from inside
        o = c + uniform(0.f, 0.99f * r) * unit();
        break;
      case 4:  // from the surface
        o = c + r * unit();
        break;
      default:  // coordinates of -0 and +0 (the centre's -0 becomes +0 in center_at)
        o = vec3(rng_() % 2 ? -0.f : 0.f, c.y, rng_() % 2 ? -0.f : c.z + 3.f * r);
        d = glm::normalize(vec3(rng_() % 2 ? -0.f : 0.f, 0.f, -1.f));
        break;
    }
    float tnear = 0.f, tfar = kInfinity;
    const float t = intersect_sphere(c, r, o, d, kInfinity);
    switch (rng_() % 10) {
      case 0: tnear = t; break;  // exactly at the root: rejected
      case 1: tnear = std::nextafter(t, -kInfinity); break;
      case 2: tfar = t; break;   // exactly at the root: that root is not taken
      case 3: tfar = std::nextafter(t, kInfinity); break;
      case 4: tfar = -kInfinity; break;  // already occluded
      case 5: tnear = -uniform(0.f, 2.f * r); break;
      case 6: tnear = std::numeric_limits<float>::quiet_NaN(); break;
      case 7: tfar = uniform(0.f, 4.f * r); break;
      default: break;
    }
    // Half the invalid lanes keep garbage for their ray too.
    if (!l.valid && rng_() % 2) return l;
    const float ray[kRayFields] = {o.x, o.y, o.z, tnear, d.x, d.y, d.z, time, tfar};
    for (int k = 0; k <= kTfar; ++k) l.f[k] = bits(ray[k]);
    l.f[kMask] = 0xFFFFFFFFu;
    return l;
  }

 private:
  std::mt19937 rng_;
};

template <class RayHitK, class RayK>
void expect_packets_match(const Sphere& sphere, int packets, uint32_t seed) {
  constexpr int kN = sizeof(std::declval<RayK>().tfar) / 4;
  Rays rays(seed);
  for (int p = 0; p < packets; ++p) {
    std::vector<Lane> lanes;
    for (int i = 0; i < kN; ++i) {
      const float time = rays.uniform(0.f, 1.f);
      lanes.push_back(rays.lane(sphere.center_at(time), sphere.radius(), time));
    }
    void* user = const_cast<Sphere*>(&sphere);
    expect_intersect_lanes_match<RayHitK>(sphere_intersect_fn, user, lanes, kPrim, kGeom, kInst);
    expect_occluded_lanes_match<RayK>(sphere_occluded_fn, user, lanes, kPrim, kGeom);
    if (testing::Test::HasFatalFailure()) return;
  }
}

void expect_all_widths_match(const Sphere& sphere) {
  expect_packets_match<RTCRayHit16, RTCRay16>(sphere, 3000, 1);
  expect_packets_match<RTCRayHit8, RTCRay8>(sphere, 1000, 2);
  expect_packets_match<RTCRayHit4, RTCRay4>(sphere, 1000, 3);
}

TEST(SpherePacket, StaticSphereLanesMatchSingleRays) {
  for (const SphereDesc& desc :
       {SphereDesc{vec3(0.f), 1.f}, SphereDesc{vec3(3.f, -1.f, 20.f), 0.01f},
        SphereDesc{vec3(-200.f, 50.f, 7.f), 150.f}}) {
    expect_all_widths_match(Sphere(desc, ShapeContext{}));
    if (HasFatalFailure()) return;
  }
  // A centre with -0 coordinates (a -0 offset keeps them), which center_at makes +0.
  ShapeContext ctx;
  ctx.offset = vec3(-0.f);
  expect_all_widths_match(Sphere(SphereDesc{vec3(-0.f, 2.f, -0.f), 0.5f}, ctx));
}

TEST(SpherePacket, MovingSphereLanesMatchSingleRays) {
  ShapeContext ctx;
  ctx.motion.motion.velocity = vec3(0.3f, -1.7f, 0.25f);
  ctx.motion.motion.acceleration = vec3(2.f, 0.f, -0.9f);
  ctx.motion.shutter_open = 0.25f;
  ctx.motion.shutter_span = 0.6f;
  expect_all_widths_match(Sphere(SphereDesc{vec3(0.5f, 1.f, -2.f), 0.8f}, ctx));
}

// A lane whose ray grazes, or starts inside, must take the scalar root rule: the nearer root in
// (0, tfar), else the farther, and a hit written only past tnear.
TEST(SpherePacket, InsideRayTakesTheFarRoot) {
  const Sphere sphere(SphereDesc{vec3(0.f), 1.f}, ShapeContext{});
  RTCRayHit16 rh;
  std::memset(&rh, 0, sizeof rh);
  int valid[16];
  for (int i = 0; i < 16; ++i) {
    valid[i] = -1;
    rh.ray.org_z[i] = 0.25f * static_cast<float>(i % 4);  // inside: the far root is 1 - z
    rh.ray.dir_z[i] = 1.f;
    rh.ray.tfar[i] = kInfinity;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  const RTCIntersectFunctionNArguments args{valid, const_cast<Sphere*>(&sphere), kPrim, &ctx,
                                            reinterpret_cast<RTCRayHitN*>(&rh), 16, kGeom};
  sphere_intersect_fn(&args);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(rh.hit.geomID[i], kGeom);
    EXPECT_FLOAT_EQ(rh.ray.tfar[i], 1.f - rh.ray.org_z[i]);
    EXPECT_FLOAT_EQ(rh.hit.Ng_z[i], 1.f);
  }
}

}  // namespace
}  // namespace penumbra::test
