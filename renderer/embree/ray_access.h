#pragma once
// Reading one ray of an Embree ray packet (the RTCRayN accessors) as our vector types.
#include <embree3/rtcore.h>

#include "renderer/core/math.h"

namespace penumbra {

inline vec3 embree_ray_origin(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i));
}
inline vec3 embree_ray_direction(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i));
}

}  // namespace penumbra
