#pragma once
// Our rays as Embree's single-ray records, and one ray of an Embree ray packet (the RTCRayN
// accessors) read back as our vector types.
#include <embree3/rtcore.h>

#include "renderer/core/bounds.h"
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

// The ids a user geometry's packet callback writes into the lanes it hits (the primitive and
// geometry of the call, the instance of its context), taken once per call.
struct UserHitIds {
  unsigned prim, geom, inst;
};
inline UserHitIds user_hit_ids(const RTCIntersectFunctionNArguments* args) {
  return UserHitIds{args->primID, args->geomID, args->context->instID[0]};
}

// Whether a user geometry's hit at exactly the t of the ray's current hit replaces it: when it
// comes first in (instance, geometry, primitive) order. Coincident surfaces (a duplicated
// object) tie to the bit, as do two faces of one mesh at the edge they share, and Embree visits
// them in a different order for a packet than for a single ray; with this rule the lowest ids
// win whatever the order, so both drivers see the same hit (tests/stress/wavefront_driver_test.cpp,
// coincident surfaces). No current hit: no tie.
[[gnu::always_inline]] inline Mask tie_wins(unsigned inst, unsigned geom, unsigned prim,
                                            unsigned hit_inst, unsigned hit_geom,
                                            unsigned hit_prim) {
  return mask(hit_geom != RTC_INVALID_GEOMETRY_ID) &
         (mask(inst < hit_inst) |
          (mask(inst == hit_inst) &
           (mask(geom < hit_geom) | (mask(geom == hit_geom) & mask(prim < hit_prim)))));
}

// A user geometry's box as its bounds callback reports it.
inline void write_embree_bounds(const Bounds3& b, RTCBounds* out) {
  out->lower_x = b.lo.x;
  out->lower_y = b.lo.y;
  out->lower_z = b.lo.z;
  out->upper_x = b.hi.x;
  out->upper_y = b.hi.y;
  out->upper_z = b.hi.z;
}

// A user geometry's hit on lane i of an intersect call over n rays (n = 1: rtcIntersect1): the
// ray's new tfar, the hit's geometric normal, (u, v) and the primitive, geometry and instance ids.
inline void record_user_hit(const RTCIntersectFunctionNArguments* args, unsigned n, unsigned i,
                            float t, const vec3& ng, float u, float v) {
  RTCRayN_tfar(RTCRayHitN_RayN(args->rayhit, n), n, i) = t;
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
  RTCHitN_Ng_x(hit, n, i) = ng.x;
  RTCHitN_Ng_y(hit, n, i) = ng.y;
  RTCHitN_Ng_z(hit, n, i) = ng.z;
  RTCHitN_u(hit, n, i) = u;
  RTCHitN_v(hit, n, i) = v;
  RTCHitN_primID(hit, n, i) = args->primID;
  RTCHitN_geomID(hit, n, i) = args->geomID;
  RTCHitN_instID(hit, n, i, 0) = args->context->instID[0];
}

inline vec3 embree_ray_origin(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i));
}
inline vec3 embree_ray_direction(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i));
}

}  // namespace penumbra
