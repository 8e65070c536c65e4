#include "renderer/shapes/parallelogram.h"

#include "renderer/core/lane.h"
#include "renderer/core/ray.h"
#include "renderer/core/simd_clones.h"
#include "renderer/embree/ray_access.h"

namespace penumbra {
namespace {

// What a lane reads, flat (the packet loops vectorise over the rays, not over these).
struct ParallelogramLanes {
  float qx, qy, qz;  // corner
  double nx, ny, nz;
  float dux, duy, duz, dvx, dvy, dvz;
};

ParallelogramLanes lanes_of(const Parallelogram& q) {
  return ParallelogramLanes{q.origin.x, q.origin.y, q.origin.z, q.normal.x, q.normal.y,
                            q.normal.z,   q.du.x,     q.du.y,     q.du.z,     q.dv.x,
                            q.dv.y,       q.dv.z};
}

// The test on one ray: its t if it meets the parallelogram in (tnear, tfar), or at tfar itself
// when `wins_tie` (embree/ray_access.h, tie_wins), else -infinity, which fails `t > tnear`;
// (s, t) in *s_out, *t_out. Every lane computes every value and selects at the end, so a single
// ray and a packet's lane give the same bits (this file is compiled without FMA contraction,
// renderer/CMakeLists.txt).
[[gnu::always_inline]] inline float lane_test(const ParallelogramLanes& q, float ox, float oy,
                                              float oz, float dx, float dy, float dz,
                                              float tnear, float tfar, Mask wins_tie,
                                              float* s_out, float* t_out) {
  // Sign of t in double: products of floats are exact there, so a ray leaving the plane (its
  // origin beyond the hit point's error bound) is never ahead of it.
  const double wx = double(q.qx) - double(ox), wy = double(q.qy) - double(oy),
               wz = double(q.qz) - double(oz);
  const double num = (q.nx * wx + q.ny * wy) + q.nz * wz;
  const double den = (q.nx * double(dx) + q.ny * double(dy)) + q.nz * double(dz);
  const Mask ahead = (mask(num > 0.0) & mask(den > 0.0)) | (mask(num < 0.0) & mask(den < 0.0));
  const float t = float(num) / float(den);
  const float px = (ox + t * dx) - q.qx, py = (oy + t * dy) - q.qy, pz = (oz + t * dz) - q.qz;
  const float s = (px * q.dux + py * q.duy) + pz * q.duz;
  const float r = (px * q.dvx + py * q.dvy) + pz * q.dvz;
  constexpr float lo = -Parallelogram::kEdgeTolerance, hi = 1.f + Parallelogram::kEdgeTolerance;
  const Mask inside = mask(s >= lo) & mask(s <= hi) & mask(r >= lo) & mask(r <= hi);
  // A ray in the plane (num = den = 0) has a NaN t, which every comparison here rejects.
  const Mask nearer = mask(t < tfar) | (mask(t == tfar) & wins_tie);
  const Mask hit = ahead & inside & mask(t > tnear) & nearer;
  *s_out = s;
  *t_out = r;
  return when(hit, t, -kInfinity);
}

template <unsigned kN>
inline void intersect_one(const RTCIntersectFunctionNArguments* args, unsigned i) {
  const unsigned n = kN ? kN : args->N;
  if (args->valid[i] == 0) return;
  const ParallelogramLanes q = lanes_of(*static_cast<const Parallelogram*>(args->geometryUserPtr));
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, n);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
  float s, r;
  const Mask tie = tie_wins(args->context->instID[0], args->geomID, RTCHitN_instID(hit, n, i, 0),
                            RTCHitN_geomID(hit, n, i));
  const float t = lane_test(q, RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i),
                            RTCRayN_org_z(ray, n, i), RTCRayN_dir_x(ray, n, i),
                            RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i),
                            RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), tie, &s, &r);
  if (!(t > RTCRayN_tnear(ray, n, i))) return;
  record_user_hit(args, n, i, t, vec3(float(q.nx), float(q.ny), float(q.nz)), s, r);
}

template <unsigned kN>
inline void occluded_one(const RTCOccludedFunctionNArguments* args, unsigned i) {
  const unsigned n = kN ? kN : args->N;
  if (args->valid[i] == 0) return;
  const ParallelogramLanes q = lanes_of(*static_cast<const Parallelogram*>(args->geometryUserPtr));
  RTCRayN* ray = args->ray;
  float s, r;
  const float t = lane_test(q, RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i),
                            RTCRayN_org_z(ray, n, i), RTCRayN_dir_x(ray, n, i),
                            RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i),
                            RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), 0, &s, &r);
  if (t > RTCRayN_tnear(ray, n, i)) RTCRayN_tfar(ray, n, i) = -kInfinity;
}

// Packets of 4, 8 and 16 rays in SIMD lanes; a lane that does not hit keeps its old values.
template <class RayHitK>
[[gnu::always_inline]] inline void intersect_packet(const ParallelogramLanes& q,
                                                    const int* __restrict valid,
                                                    RayHitK* __restrict rh, UserHitIds ids) {
  constexpr int kN = sizeof(rh->ray.tfar) / sizeof(float);
  auto& ray = rh->ray;
  auto& hit = rh->hit;
  const float nx = float(q.nx), ny = float(q.ny), nz = float(q.nz);
  for (int i = 0; i < kN; ++i) {
    float s, r;
    const Mask tie = tie_wins(ids.inst, ids.geom, hit.instID[0][i], hit.geomID[i]);
    const float t = lane_test(q, ray.org_x[i], ray.org_y[i], ray.org_z[i], ray.dir_x[i],
                              ray.dir_y[i], ray.dir_z[i], ray.tnear[i], ray.tfar[i], tie, &s, &r);
    const Mask m = mask(valid[i] != 0) & mask(t > ray.tnear[i]);
    ray.tfar[i] = when(m, t, ray.tfar[i]);
    hit.Ng_x[i] = when(m, nx, hit.Ng_x[i]);
    hit.Ng_y[i] = when(m, ny, hit.Ng_y[i]);
    hit.Ng_z[i] = when(m, nz, hit.Ng_z[i]);
    hit.u[i] = when(m, s, hit.u[i]);
    hit.v[i] = when(m, r, hit.v[i]);
    hit.primID[i] = when(m, ids.prim, hit.primID[i]);
    hit.geomID[i] = when(m, ids.geom, hit.geomID[i]);
    hit.instID[0][i] = when(m, ids.inst, hit.instID[0][i]);
  }
}

template <class RayK>
[[gnu::always_inline]] inline void occluded_packet(const ParallelogramLanes& q,
                                                   const int* __restrict valid,
                                                   RayK* __restrict ray) {
  constexpr int kN = sizeof(ray->tfar) / sizeof(float);
  for (int i = 0; i < kN; ++i) {
    float s, r;
    const float t = lane_test(q, ray->org_x[i], ray->org_y[i], ray->org_z[i], ray->dir_x[i],
                              ray->dir_y[i], ray->dir_z[i], ray->tnear[i], ray->tfar[i], 0, &s,
                              &r);
    const Mask m = mask(valid[i] != 0) & mask(t > ray->tnear[i]);
    ray->tfar[i] = when(m, -kInfinity, ray->tfar[i]);
  }
}

PENUMBRA_SIMD_CLONES
void packet_intersect16(const ParallelogramLanes& q, const int* __restrict valid,
                 RTCRayHit16* __restrict rh, UserHitIds ids) {
  intersect_packet(q, valid, rh, ids);
}
PENUMBRA_SIMD_CLONES
void packet_intersect8(const ParallelogramLanes& q, const int* __restrict valid,
                RTCRayHit8* __restrict rh, UserHitIds ids) {
  intersect_packet(q, valid, rh, ids);
}
PENUMBRA_SIMD_CLONES
void packet_intersect4(const ParallelogramLanes& q, const int* __restrict valid,
                RTCRayHit4* __restrict rh, UserHitIds ids) {
  intersect_packet(q, valid, rh, ids);
}
PENUMBRA_SIMD_CLONES
void packet_occluded16(const ParallelogramLanes& q, const int* __restrict valid,
                      RTCRay16* __restrict ray) {
  occluded_packet(q, valid, ray);
}
PENUMBRA_SIMD_CLONES
void packet_occluded8(const ParallelogramLanes& q, const int* __restrict valid,
                      RTCRay8* __restrict ray) {
  occluded_packet(q, valid, ray);
}
PENUMBRA_SIMD_CLONES
void packet_occluded4(const ParallelogramLanes& q, const int* __restrict valid,
                      RTCRay4* __restrict ray) {
  occluded_packet(q, valid, ray);
}

}  // namespace

Parallelogram::Parallelogram(const QuadDesc& q)
    : origin(q.origin), u(q.u), v(q.v), normal(glm::cross(dvec3(q.u), dvec3(q.v))) {
  // Dual vectors of u and v in their plane: du . u = 1, du . v = 0, dv . v = 1, dv . u = 0.
  const dvec3 n = normal;
  const double n2 = glm::dot(n, n);
  du = n2 > 0.0 ? vec3(glm::cross(dvec3(v), n) / n2) : vec3(0.f);
  dv = n2 > 0.0 ? vec3(glm::cross(n, dvec3(u)) / n2) : vec3(0.f);
  const vec3 corners[4] = {origin, origin + u, origin + v, origin + u + v};
  for (const vec3& c : corners) bounds.extend(c);
  // The tolerance's overhang plus the rounding of the corners' sums.
  const vec3 pad = kEdgeTolerance * (abs_components(u) + abs_components(v)) +
                   gamma_bound(4) * (abs_components(origin) + abs_components(u) + abs_components(v));
  bounds.lo -= pad;
  bounds.hi += pad;
}

int Parallelogram::flat_axis() const {
  for (int k = 0; k < 3; ++k)
    if (u[k] == 0.f && v[k] == 0.f) return k;
  return -1;
}

void Parallelogram::thicken() {
  // As thick in every axis as the rounding of a distance across the quad, so that a ray's entry
  // into the box comes before its hit on the quad whatever Embree's slab test rounds.
  const float pad = gamma_bound(4) * (glm::length(origin) + glm::length(u) + glm::length(v));
  bounds.lo -= vec3(pad);
  bounds.hi += vec3(pad);
}

void parallelogram_bounds_fn(const RTCBoundsFunctionArguments* args) {
  write_embree_bounds(static_cast<const Parallelogram*>(args->geometryUserPtr)->bounds,
                      args->bounds_o);
}

void parallelogram_intersect_fn(const RTCIntersectFunctionNArguments* args) {
  if (args->N == 1) return intersect_one<1>(args, 0);
  const ParallelogramLanes q = lanes_of(*static_cast<const Parallelogram*>(args->geometryUserPtr));
  const UserHitIds ids = user_hit_ids(args);
  // An RTCRayHitN of a width known here is that width's RTCRayHitK (embree3/rtcore_ray.h).
  switch (args->N) {
    case 16:
      return packet_intersect16(q, args->valid, reinterpret_cast<RTCRayHit16*>(args->rayhit), ids);
    case 8:
      return packet_intersect8(q, args->valid, reinterpret_cast<RTCRayHit8*>(args->rayhit), ids);
    case 4:
      return packet_intersect4(q, args->valid, reinterpret_cast<RTCRayHit4*>(args->rayhit), ids);
    default:
      for (unsigned i = 0; i < args->N; ++i) intersect_one<0>(args, i);
  }
}

void parallelogram_occluded_fn(const RTCOccludedFunctionNArguments* args) {
  if (args->N == 1) return occluded_one<1>(args, 0);
  const ParallelogramLanes q = lanes_of(*static_cast<const Parallelogram*>(args->geometryUserPtr));
  switch (args->N) {
    case 16:
      return packet_occluded16(q, args->valid, reinterpret_cast<RTCRay16*>(args->ray));
    case 8:
      return packet_occluded8(q, args->valid, reinterpret_cast<RTCRay8*>(args->ray));
    case 4:
      return packet_occluded4(q, args->valid, reinterpret_cast<RTCRay4*>(args->ray));
    default:
      for (unsigned i = 0; i < args->N; ++i) occluded_one<0>(args, i);
  }
}

}  // namespace penumbra
