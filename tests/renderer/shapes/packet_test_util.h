#pragma once
// Embree ray packets as raw lanes, for the tests that compare a user geometry's packet callbacks
// with the same callbacks on one ray at a time (sphere_packet_test.cpp, parallelogram_test.cpp).
#include <embree3/rtcore.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace penumbra::test {

// An RTCRayHitK is 12 ray fields then 7 + instance-level hit fields, each K 32-bit lanes; one
// ray (RTCRayHit) is the same with K = 1. The tests move lanes as raw bits.
inline constexpr int kRayFields = 12;
inline constexpr int kHitFields = 7 + RTC_MAX_INSTANCE_LEVEL_COUNT;
static_assert(sizeof(RTCRayHit) == (kRayFields + kHitFields) * 4);
static_assert(sizeof(RTCRayHit16) == (kRayFields + kHitFields) * 4 * 16);
enum Field { kOrgX, kOrgY, kOrgZ, kTnear, kDirX, kDirY, kDirZ, kTime, kTfar, kMask };

inline uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

// One ray's fields (and garbage in its hit fields), and whether its lane is valid.
struct Lane {
  uint32_t f[kRayFields + kHitFields];
  bool valid;
};

// A packet of K lanes through the packet callback, each lane through the N = 1 callback, and
// their fields compared bit for bit.
template <class RayHitK>
void expect_intersect_lanes_match(RTCIntersectFunctionN fn, void* user,
                                  const std::vector<Lane>& lanes, unsigned prim, unsigned geom,
                                  unsigned inst) {
  constexpr int kN = sizeof(std::declval<RayHitK>().ray.tfar) / 4;
  ASSERT_EQ(lanes.size(), static_cast<size_t>(kN));
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.instID[0] = inst;
  uint32_t packet[(kRayFields + kHitFields) * kN];
  int valid[kN];
  for (int i = 0; i < kN; ++i) {
    for (int k = 0; k < kRayFields + kHitFields; ++k) packet[k * kN + i] = lanes[i].f[k];
    valid[i] = lanes[i].valid ? -1 : 0;
  }
  RayHitK rh;
  std::memcpy(&rh, packet, sizeof rh);
  const RTCIntersectFunctionNArguments args{valid, user, prim, &ctx,
                                            reinterpret_cast<RTCRayHitN*>(&rh), kN, geom};
  fn(&args);
  std::memcpy(packet, &rh, sizeof rh);
  for (int i = 0; i < kN; ++i) {
    RTCRayHit one;
    std::memcpy(&one, lanes[i].f, sizeof one);
    int one_valid = -1;
    if (lanes[i].valid) {
      const RTCIntersectFunctionNArguments a1{&one_valid, user, prim,
                                              &ctx, reinterpret_cast<RTCRayHitN*>(&one), 1, geom};
      fn(&a1);
    }
    uint32_t want[kRayFields + kHitFields];
    std::memcpy(want, &one, sizeof want);
    for (int k = 0; k < kRayFields + kHitFields; ++k)
      ASSERT_EQ(packet[k * kN + i], want[k]) << "width " << kN << ", lane " << i << ", field " << k
                                             << (lanes[i].valid ? "" : " (invalid lane)");
  }
}

template <class RayK>
void expect_occluded_lanes_match(RTCOccludedFunctionN fn, void* user,
                                 const std::vector<Lane>& lanes, unsigned prim, unsigned geom) {
  constexpr int kN = sizeof(std::declval<RayK>().tfar) / 4;
  ASSERT_EQ(lanes.size(), static_cast<size_t>(kN));
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  uint32_t packet[kRayFields * kN];
  int valid[kN];
  for (int i = 0; i < kN; ++i) {
    for (int k = 0; k < kRayFields; ++k) packet[k * kN + i] = lanes[i].f[k];
    valid[i] = lanes[i].valid ? -1 : 0;
  }
  RayK ray;
  std::memcpy(&ray, packet, sizeof ray);
  const RTCOccludedFunctionNArguments args{valid, user, prim, &ctx,
                                           reinterpret_cast<RTCRayN*>(&ray), kN, geom};
  fn(&args);
  std::memcpy(packet, &ray, sizeof ray);
  for (int i = 0; i < kN; ++i) {
    RTCRay one;
    std::memcpy(&one, lanes[i].f, sizeof one);
    int one_valid = -1;
    if (lanes[i].valid) {
      const RTCOccludedFunctionNArguments a1{&one_valid, user, prim, &ctx,
                                             reinterpret_cast<RTCRayN*>(&one), 1, geom};
      fn(&a1);
    }
    uint32_t want[kRayFields];
    std::memcpy(want, &one, sizeof want);
    for (int k = 0; k < kRayFields; ++k)
      ASSERT_EQ(packet[k * kN + i], want[k]) << "width " << kN << ", lane " << i << ", field " << k
                                             << (lanes[i].valid ? "" : " (invalid lane)");
  }
}

}  // namespace penumbra::test
