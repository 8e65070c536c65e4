#pragma once
// Our rays as Embree's single-ray records, and one ray of an Embree ray packet (the RTCRayN
// accessors) read back as our vector types.
#include <embree3/rtcore.h>

#include "renderer/core/lane.h"
#include "renderer/core/math.h"
#include "renderer/core/ray.h"

namespace penumbra {

// An RTCRayHit for rtcIntersect1: the ray from t = 0 to ray.t_max at ray.time, no hit yet.
inline RTCRayHit embree_ray_hit(const Ray& ray) {
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.dir_x = ray.direction.x;
  rh.ray.dir_y = ray.direction.y;
  rh.ray.dir_z = ray.direction.z;
  rh.ray.tnear = 0.f;
  rh.ray.tfar = ray.t_max;
  rh.ray.time = ray.time;
  rh.ray.mask = 0xFFFFFFFFu;  // Debian's Embree is built with ray masks: 0 would hit nothing
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// Calls fn(n, i) for every lane i of a filter call over n rays; a single ray (rtcIntersect1,
// rtcOccluded1) as fn(1, 0), so the RTCRayN/RTCHitN accessors fold to plain fields.
template <class Fn>
[[gnu::always_inline]] inline void for_each_filter_lane(const RTCFilterFunctionNArguments* args,
                                                        Fn&& fn) {
  if (args->N == 1) {
    fn(1u, 0u);
    return;
  }
  for (unsigned i = 0; i < args->N; ++i) fn(args->N, i);
}

// Whether a user geometry's hit at exactly the t of the ray's current hit replaces it: when it
// comes first in (instance, geometry) order. Coincident surfaces (a duplicated object) tie to the
// bit, and Embree visits them in a different order for a packet than for a single ray; with this
// rule the lowest ids win whatever the order, so both drivers see the same hit
// (tests/stress/wavefront_driver_test.cpp, coincident surfaces). No current hit: no tie.
[[gnu::always_inline]] inline Mask tie_wins(unsigned inst, unsigned geom, unsigned hit_inst,
                                            unsigned hit_geom) {
  return mask(hit_geom != RTC_INVALID_GEOMETRY_ID) &
         (mask(inst < hit_inst) | (mask(inst == hit_inst) & mask(geom < hit_geom)));
}

inline vec3 embree_ray_origin(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i));
}
inline vec3 embree_ray_direction(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i));
}

}  // namespace penumbra
