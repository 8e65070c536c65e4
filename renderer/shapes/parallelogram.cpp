#include "renderer/shapes/parallelogram.h"

#include "renderer/core/lane.h"
#include "renderer/core/ray.h"
#include "renderer/core/simd_clones.h"
#include "renderer/embree/ray_access.h"

namespace penumbra {
namespace {

// The geometry's user data is its array of parallelograms, one per Embree primitive.
template <class Args>
const Parallelogram& parallelogram_of(const Args* args) {
  return static_cast<const Parallelogram*>(args->geometryUserPtr)[args->primID];
}

// What a lane reads, flat (the packet loops vectorise over the rays, not over these).
struct ParallelogramLanes {
  float qx, qy, qz;  // corner
  double nx, ny, nz;
  float dux, duy, duz, dvx, dvy, dvz;
  float lo, hi;  // the (s, t) range: [0, 1] with exact edges, else widened by the tolerance
  const Parallelogram* exact;  // with exact edges, the parallelogram, else null
};

ParallelogramLanes lanes_of(const Parallelogram& q) {
  const float tol = q.exact_edges ? 0.f : Parallelogram::kEdgeTolerance;
  return ParallelogramLanes{q.origin.x, q.origin.y, q.origin.z, q.normal.x, q.normal.y,
                            q.normal.z,   q.du.x,     q.du.y,     q.du.z,     q.dv.x,
                            q.dv.y,       q.dv.z,     -tol,       1.f + tol,
                            q.exact_edges ? &q : nullptr};
}

// Whether the ray passes inside edge P -> Q of a face it meets from the side of `den`'s sign:
// the Pluecker sign of ((P - o) x (Q - o)) . d, in double. Reversing P and Q negates every
// product's difference exactly, so a neighbour sharing the edge gets the opposite answer (zero:
// both), whatever the rounding.
bool inside_edge(const vec3& p, const vec3& q, const dvec3& o, const dvec3& d, double den) {
  const dvec3 a = dvec3(p) - o, b = dvec3(q) - o;
  const double e = (a.y * b.z - a.z * b.y) * d.x + (a.z * b.x - a.x * b.z) * d.y +
                   (a.x * b.y - a.y * b.x) * d.z;
  return den > 0.0 ? e >= 0.0 : e <= 0.0;
}

// With exact edges: whether (s, t) lies within the tolerance of an edge, where the test's own
// rounding could decide either way.
[[gnu::always_inline]] inline Mask near_edge(float s, float r) {
  constexpr float tol = Parallelogram::kEdgeTolerance;
  return mask(std::fabs(s) <= tol) | mask(std::fabs(s - 1.f) <= tol) |
         mask(std::fabs(r) <= tol) | mask(std::fabs(r - 1.f) <= tol);
}

// The decision for a ray whose (s, t) is near an edge: each edge within the tolerance by the
// side of its line the ray passes, the others by (s, t) as usual.
bool inside_near_edges(const Parallelogram& q, const vec3& o, const vec3& d, float s, float r) {
  constexpr float tol = Parallelogram::kEdgeTolerance;
  const dvec3 od(o), dd(d);
  const double den = glm::dot(q.normal, dd);
  const vec3* c = q.corners;  // (0, 0), (1, 0), (1, 1), (0, 1)
  const bool t0 = std::fabs(r) <= tol ? inside_edge(c[0], c[1], od, dd, den) : r >= 0.f;
  const bool s1 = std::fabs(s - 1.f) <= tol ? inside_edge(c[1], c[2], od, dd, den) : s <= 1.f;
  const bool t1 = std::fabs(r - 1.f) <= tol ? inside_edge(c[2], c[3], od, dd, den) : r <= 1.f;
  const bool s0 = std::fabs(s) <= tol ? inside_edge(c[3], c[0], od, dd, den) : s >= 0.f;
  return t0 && s1 && t1 && s0;
}

// The test on one ray: its t if it meets the parallelogram in (tnear, tfar), or at tfar itself
// when `wins_tie` (embree/ray_access.h, tie_wins), else -infinity, which fails `t > tnear`;
// (s, t) in *s_out, *t_out. Every lane computes every value and selects at the end, so a single
// ray and a packet's lane give the same bits (this file is compiled without FMA contraction,
// renderer/CMakeLists.txt). With exact edges, a ray that would hit but for (s, t) near an edge
// gets -infinity and *near_out set: decide_near_edge settles it.
[[gnu::always_inline]] inline float lane_test(const ParallelogramLanes& q, float ox, float oy,
                                              float oz, float dx, float dy, float dz,
                                              float tnear, float tfar, Mask wins_tie,
                                              float* s_out, float* t_out, Mask* near_out) {
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
  const Mask inside = mask(s >= q.lo) & mask(s <= q.hi) & mask(r >= q.lo) & mask(r <= q.hi);
  // A ray in the plane (num = den = 0) has a NaN t, which every comparison here rejects.
  const Mask nearer = mask(t < tfar) | (mask(t == tfar) & wins_tie);
  const Mask candidate = ahead & mask(t > tnear) & nearer;
  const Mask near = q.exact ? candidate & near_edge(s, r) : 0;
  const Mask hit = candidate & inside & ~near;
  *s_out = s;
  *t_out = r;
  *near_out = near;
  return when(hit, t, -kInfinity);
}

// The t of a ray lane_test left near an edge: the t it computed if the edges let the ray in,
// else -infinity. Rare (a band of 1e-5 of the edge along each), so one ray at a time.
float decide_near_edge(const Parallelogram& q, float ox, float oy, float oz, float dx, float dy,
                       float dz, float tnear, float tfar, Mask wins_tie, float* s, float* r) {
  Mask near;
  ParallelogramLanes wide = lanes_of(q);
  wide.lo = -2.f;  // every (s, t) passes the range; the edges decide
  wide.hi = 2.f;
  wide.exact = nullptr;
  const float t = lane_test(wide, ox, oy, oz, dx, dy, dz, tnear, tfar, wins_tie, s, r, &near);
  if (!(t > tnear)) return -kInfinity;
  return inside_near_edges(q, vec3(ox, oy, oz), vec3(dx, dy, dz), *s, *r) ? t : -kInfinity;
}

template <unsigned kN>
inline void intersect_one(const RTCIntersectFunctionNArguments* args, unsigned i) {
  const unsigned n = kN ? kN : args->N;
  if (args->valid[i] == 0) return;
  const ParallelogramLanes q = lanes_of(parallelogram_of(args));
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, n);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
  float s, r;
  const Mask tie = tie_wins(args->context->instID[0], args->geomID, args->primID,
                            RTCHitN_instID(hit, n, i, 0), RTCHitN_geomID(hit, n, i),
                            RTCHitN_primID(hit, n, i));
  const float ox = RTCRayN_org_x(ray, n, i), oy = RTCRayN_org_y(ray, n, i),
              oz = RTCRayN_org_z(ray, n, i), dx = RTCRayN_dir_x(ray, n, i),
              dy = RTCRayN_dir_y(ray, n, i), dz = RTCRayN_dir_z(ray, n, i),
              tnear = RTCRayN_tnear(ray, n, i), tfar = RTCRayN_tfar(ray, n, i);
  Mask near;
  float t = lane_test(q, ox, oy, oz, dx, dy, dz, tnear, tfar, tie, &s, &r, &near);
  if (near) t = decide_near_edge(*q.exact, ox, oy, oz, dx, dy, dz, tnear, tfar, tie, &s, &r);
  if (!(t > tnear)) return;
  record_user_hit(args, n, i, t, vec3(float(q.nx), float(q.ny), float(q.nz)), s, r);
}

template <unsigned kN>
inline void occluded_one(const RTCOccludedFunctionNArguments* args, unsigned i) {
  const unsigned n = kN ? kN : args->N;
  if (args->valid[i] == 0) return;
  const ParallelogramLanes q = lanes_of(parallelogram_of(args));
  RTCRayN* ray = args->ray;
  float s, r;
  const float ox = RTCRayN_org_x(ray, n, i), oy = RTCRayN_org_y(ray, n, i),
              oz = RTCRayN_org_z(ray, n, i), dx = RTCRayN_dir_x(ray, n, i),
              dy = RTCRayN_dir_y(ray, n, i), dz = RTCRayN_dir_z(ray, n, i),
              tnear = RTCRayN_tnear(ray, n, i), tfar = RTCRayN_tfar(ray, n, i);
  Mask near;
  float t = lane_test(q, ox, oy, oz, dx, dy, dz, tnear, tfar, 0, &s, &r, &near);
  if (near) t = decide_near_edge(*q.exact, ox, oy, oz, dx, dy, dz, tnear, tfar, 0, &s, &r);
  if (t > tnear) RTCRayN_tfar(ray, n, i) = -kInfinity;
}

// Packets of 4, 8 and 16 rays in SIMD lanes; a lane that does not hit keeps its old values. A
// lane near an exact edge is left alone and flagged in near[i], for the caller to trace as a
// single ray.
template <class RayHitK>
[[gnu::always_inline]] inline void intersect_packet(const ParallelogramLanes& q,
                                                    const int* __restrict valid,
                                                    RayHitK* __restrict rh, UserHitIds ids,
                                                    Mask* __restrict near) {
  constexpr int kN = sizeof(rh->ray.tfar) / sizeof(float);
  auto& ray = rh->ray;
  auto& hit = rh->hit;
  const float nx = float(q.nx), ny = float(q.ny), nz = float(q.nz);
  for (int i = 0; i < kN; ++i) {
    float s, r;
    const Mask tie =
        tie_wins(ids.inst, ids.geom, ids.prim, hit.instID[0][i], hit.geomID[i], hit.primID[i]);
    Mask lane_near;
    const float t = lane_test(q, ray.org_x[i], ray.org_y[i], ray.org_z[i], ray.dir_x[i],
                              ray.dir_y[i], ray.dir_z[i], ray.tnear[i], ray.tfar[i], tie, &s, &r,
                              &lane_near);
    near[i] = mask(valid[i] != 0) & lane_near;
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
                                                   RayK* __restrict ray, Mask* __restrict near) {
  constexpr int kN = sizeof(ray->tfar) / sizeof(float);
  for (int i = 0; i < kN; ++i) {
    float s, r;
    Mask lane_near;
    const float t = lane_test(q, ray->org_x[i], ray->org_y[i], ray->org_z[i], ray->dir_x[i],
                              ray->dir_y[i], ray->dir_z[i], ray->tnear[i], ray->tfar[i], 0, &s,
                              &r, &lane_near);
    near[i] = mask(valid[i] != 0) & lane_near;
    const Mask m = mask(valid[i] != 0) & mask(t > ray->tnear[i]);
    ray->tfar[i] = when(m, -kInfinity, ray->tfar[i]);
  }
}

PENUMBRA_SIMD_CLONES
void packet_intersect16(const ParallelogramLanes& q, const int* __restrict valid, Mask* __restrict near,
                 RTCRayHit16* __restrict rh, UserHitIds ids) {
  intersect_packet(q, valid, rh, ids, near);
}
PENUMBRA_SIMD_CLONES
void packet_intersect8(const ParallelogramLanes& q, const int* __restrict valid, Mask* __restrict near,
                RTCRayHit8* __restrict rh, UserHitIds ids) {
  intersect_packet(q, valid, rh, ids, near);
}
PENUMBRA_SIMD_CLONES
void packet_intersect4(const ParallelogramLanes& q, const int* __restrict valid, Mask* __restrict near,
                RTCRayHit4* __restrict rh, UserHitIds ids) {
  intersect_packet(q, valid, rh, ids, near);
}
PENUMBRA_SIMD_CLONES
void packet_occluded16(const ParallelogramLanes& q, const int* __restrict valid, Mask* __restrict near,
                      RTCRay16* __restrict ray) {
  occluded_packet(q, valid, ray, near);
}
PENUMBRA_SIMD_CLONES
void packet_occluded8(const ParallelogramLanes& q, const int* __restrict valid, Mask* __restrict near,
                      RTCRay8* __restrict ray) {
  occluded_packet(q, valid, ray, near);
}
PENUMBRA_SIMD_CLONES
void packet_occluded4(const ParallelogramLanes& q, const int* __restrict valid, Mask* __restrict near,
                      RTCRay4* __restrict ray) {
  occluded_packet(q, valid, ray, near);
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

void Parallelogram::use_exact_edges(const vec3& c00, const vec3& c10, const vec3& c11,
                                    const vec3& c01) {
  exact_edges = true;
  corners[0] = c00;
  corners[1] = c10;
  corners[2] = c11;
  corners[3] = c01;
  // The fourth corner lies within the padding of origin + u + v (shapes/parallelogram_pairs.h),
  // but the box is the test's promise: it holds every corner.
  bounds.extend(c11);
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

EmbreeGeometry make_parallelogram_geometry(RTCDevice device, const Parallelogram* first,
                                          size_t count) {
  EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER));
  if (!geom) return geom;
  rtcSetGeometryUserPrimitiveCount(geom.get(), unsigned(count));
  rtcSetGeometryBoundsFunction(geom.get(), parallelogram_bounds_fn, nullptr);
  rtcSetGeometryIntersectFunction(geom.get(), parallelogram_intersect_fn);
  rtcSetGeometryOccludedFunction(geom.get(), parallelogram_occluded_fn);
  rtcSetGeometryUserData(geom.get(), const_cast<Parallelogram*>(first));
  rtcCommitGeometry(geom.get());
  return geom;
}

void parallelogram_bounds_fn(const RTCBoundsFunctionArguments* args) {
  write_embree_bounds(parallelogram_of(args).bounds, args->bounds_o);
}

void parallelogram_intersect_fn(const RTCIntersectFunctionNArguments* args) {
  if (args->N == 1) return intersect_one<1>(args, 0);
  const ParallelogramLanes q = lanes_of(parallelogram_of(args));
  const UserHitIds ids = user_hit_ids(args);
  Mask near[16];
  // An RTCRayHitN of a width known here is that width's RTCRayHitK (embree3/rtcore_ray.h).
  switch (args->N) {
    case 16:
      packet_intersect16(q, args->valid, near, reinterpret_cast<RTCRayHit16*>(args->rayhit), ids);
      break;
    case 8:
      packet_intersect8(q, args->valid, near, reinterpret_cast<RTCRayHit8*>(args->rayhit), ids);
      break;
    case 4:
      packet_intersect4(q, args->valid, near, reinterpret_cast<RTCRayHit4*>(args->rayhit), ids);
      break;
    default:
      for (unsigned i = 0; i < args->N; ++i) intersect_one<0>(args, i);
      return;
  }
  // The packet left these lanes untouched: the single-ray test repeats its values and settles
  // the edges.
  if (q.exact)
    for (unsigned i = 0; i < args->N; ++i)
      if (near[i]) intersect_one<0>(args, i);
}

void parallelogram_occluded_fn(const RTCOccludedFunctionNArguments* args) {
  if (args->N == 1) return occluded_one<1>(args, 0);
  const ParallelogramLanes q = lanes_of(parallelogram_of(args));
  Mask near[16];
  switch (args->N) {
    case 16:
      packet_occluded16(q, args->valid, near, reinterpret_cast<RTCRay16*>(args->ray));
      break;
    case 8:
      packet_occluded8(q, args->valid, near, reinterpret_cast<RTCRay8*>(args->ray));
      break;
    case 4:
      packet_occluded4(q, args->valid, near, reinterpret_cast<RTCRay4*>(args->ray));
      break;
    default:
      for (unsigned i = 0; i < args->N; ++i) occluded_one<0>(args, i);
      return;
  }
  if (q.exact)
    for (unsigned i = 0; i < args->N; ++i)
      if (near[i]) occluded_one<0>(args, i);
}

}  // namespace penumbra
