#include "renderer/shapes/sphere.h"

#include <cstring>

#include "renderer/core/frame.h"
#include "renderer/core/lane.h"
#include "renderer/core/simd_clones.h"
#include "renderer/embree/ray_access.h"
#include "renderer/sampling/sampling.h"
#include "renderer/shapes/sphere_sample.h"

namespace penumbra {
namespace {

void sphere_bounds_fn(const RTCBoundsFunctionArguments* args) {
  const auto& sphere = *static_cast<const Sphere*>(args->geometryUserPtr);
  write_embree_bounds(sphere.embree_bounds(), args->bounds_o);
}

// One ray of a packet of kN (0: the packet's run-time width). rtcIntersect1/rtcOccluded1 call
// with N = 1, for which the RTCRayN accessors fold to plain fields once N is a constant.
template <unsigned kN>
inline void sphere_intersect_one(const RTCIntersectFunctionNArguments* args, unsigned i) {
  const unsigned n = kN ? kN : args->N;
  if (args->valid[i] == 0) return;
  const auto& sphere = *static_cast<const Sphere*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, n);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
  const vec3 o = embree_ray_origin(ray, n, i), d = embree_ray_direction(ray, n, i);
  const float t_far = RTCRayN_tfar(ray, n, i);
  const vec3 c = sphere.center_at(RTCRayN_time(ray, n, i));
  const bool tie = tie_wins(args->context->instID[0], args->geomID, args->primID,
                            RTCHitN_instID(hit, n, i, 0), RTCHitN_geomID(hit, n, i),
                            RTCHitN_primID(hit, n, i)) != 0;
  const float t = intersect_sphere(c, sphere.radius(), o, d, t_far, tie);
  if (t <= RTCRayN_tnear(ray, n, i)) return;
  record_user_hit(args, n, i, t, o + t * d - c, 0.f, 0.f);
}

template <unsigned kN>
inline void sphere_occluded_one(const RTCOccludedFunctionNArguments* args, unsigned i) {
  const unsigned n = kN ? kN : args->N;
  if (args->valid[i] == 0) return;
  const auto& sphere = *static_cast<const Sphere*>(args->geometryUserPtr);
  RTCRayN* ray = args->ray;
  const vec3 o = embree_ray_origin(ray, n, i), d = embree_ray_direction(ray, n, i);
  float& t_far = RTCRayN_tfar(ray, n, i);
  const vec3 c = sphere.center_at(RTCRayN_time(ray, n, i));
  const float t = intersect_sphere(c, sphere.radius(), o, d, t_far);
  if (t > RTCRayN_tnear(ray, n, i)) t_far = -kInfinity;
}

// Packets of 4, 8 and 16 rays (rtcIntersect16/rtcOccluded16 give Embree's callbacks whole
// packets) in SIMD lanes: every lane computes, results are selected under the lane's mask, and a
// lane that does not hit gets its old values back. The arithmetic is the scalar path's operation
// for operation (center_at, intersect_sphere, o + t*d - c; glm's dot sums x, y, z in order), and
// this file is compiled without FMA contraction (renderer/CMakeLists.txt), so every lane is the
// single ray's result to the bit. GCC 12 vectorises the loops in the AVX2 and AVX-512 clones; in
// the baseline clone it leaves the intersect loop scalar (control flow it does not if-convert).
struct SphereLanes {
  float cx, cy, cz, radius;
  bool moving;
  float vx, vy, vz;     // velocity
  float hax, hay, haz;  // 0.5f * acceleration: displacement's product, done once
  float shutter_open, shutter_span;
};

SphereLanes sphere_lanes(const Sphere& sphere) {
  const vec3 c = sphere.center(), v = sphere.motion().motion.velocity;
  const vec3 ha = 0.5f * sphere.motion().motion.acceleration;
  const ShapeMotion& m = sphere.motion();
  return SphereLanes{c.x, c.y, c.z, sphere.radius(), !m.is_static(), v.x, v.y, v.z, ha.x, ha.y,
                     ha.z, m.shutter_open, m.shutter_span};
}

template <bool kMoving>
[[gnu::always_inline]] inline void lane_center(const SphereLanes& s, float time, float* cx,
                                               float* cy, float* cz) {
  if constexpr (kMoving) {
    // center_ + motion.displacement(shutter_open + time * shutter_span).
    const float t = s.shutter_open + time * s.shutter_span;
    const float tt = t * t;
    *cx = s.cx + (s.vx * t + s.hax * tt);
    *cy = s.cy + (s.vy * t + s.hay * tt);
    *cz = s.cz + (s.vz * t + s.haz * tt);
  } else {
    // center_ + vec3(0.f), as center_at (which turns a -0 coordinate into +0).
    *cx = s.cx + 0.f;
    *cy = s.cy + 0.f;
    *cz = s.cz + 0.f;
  }
}

// std::copysign as integer bit operations: the same bits, in a form every clone vectorises.
[[gnu::always_inline]] inline float lane_copysign(float magnitude, float sign) {
  uint32_t m, s;
  std::memcpy(&m, &magnitude, sizeof m);
  std::memcpy(&s, &sign, sizeof s);
  const uint32_t r = (m & 0x7fffffffu) | (s & 0x80000000u);
  float out;
  std::memcpy(&out, &r, sizeof out);
  return out;
}

// intersect_sphere on one lane; a lane that misses takes the square root of a negative disc and
// selects it away. The swap `if (t0 > t1)` is two selects on the same comparison, so with a NaN
// root neither swaps, as in the scalar code (a sphere's rays are finite: NaNs come only from the
// garbage of invalid lanes).
[[gnu::always_inline]] inline float lane_intersect_sphere(float cx, float cy, float cz,
                                                          float radius, float ox, float oy,
                                                          float oz, float dx, float dy, float dz,
                                                          float t_max, Mask take_equal) {
  const float fx = ox - cx, fy = oy - cy, fz = oz - cz;
  const float b = -((fx * dx + fy * dy) + fz * dz);
  const float lx = fx + b * dx, ly = fy + b * dy, lz = fz + b * dz;
  const float r2 = radius * radius;
  const float disc = r2 - ((lx * lx + ly * ly) + lz * lz);
  const float c = ((fx * fx + fy * fy) + fz * fz) - r2;
  const float q = b + lane_copysign(std::sqrt(disc), b);
  const float t0 = when(mask(q != 0.f), c / q, 0.f);
  const float t1 = q;
  const Mask swap = mask(t0 > t1);
  const float lo = when(swap, t1, t0), hi = when(swap, t0, t1);
  const Mask lo_in = mask(lo > 0.f) & (mask(lo < t_max) | (take_equal & mask(lo == t_max)));
  const Mask hi_in = mask(hi > 0.f) & (mask(hi < t_max) | (take_equal & mask(hi == t_max)));
  return when(mask(disc < 0.f), -1.f, when(lo_in, lo, when(hi_in, hi, -1.f)));
}

template <class RayHitK, bool kMoving>
[[gnu::always_inline]] inline void intersect_lanes(const SphereLanes& s,
                                                   const int* __restrict valid,
                                                   RayHitK* __restrict rh, UserHitIds ids) {
  constexpr int kN = sizeof(rh->ray.tfar) / sizeof(float);
  auto& ray = rh->ray;
  auto& hit = rh->hit;
  for (int i = 0; i < kN; ++i) {
    float cx, cy, cz;
    lane_center<kMoving>(s, ray.time[i], &cx, &cy, &cz);
    const float ox = ray.org_x[i], oy = ray.org_y[i], oz = ray.org_z[i];
    const float dx = ray.dir_x[i], dy = ray.dir_y[i], dz = ray.dir_z[i];
    const Mask tie =
        tie_wins(ids.inst, ids.geom, ids.prim, hit.instID[0][i], hit.geomID[i], hit.primID[i]);
    const float t =
        lane_intersect_sphere(cx, cy, cz, s.radius, ox, oy, oz, dx, dy, dz, ray.tfar[i], tie);
    // The scalar rejection `t <= tnear`, negated (not t > tnear: they differ for a NaN tnear).
    const Mask m = mask(valid[i] != 0) & ~mask(t <= ray.tnear[i]);
    ray.tfar[i] = when(m, t, ray.tfar[i]);
    hit.Ng_x[i] = when(m, (ox + t * dx) - cx, hit.Ng_x[i]);
    hit.Ng_y[i] = when(m, (oy + t * dy) - cy, hit.Ng_y[i]);
    hit.Ng_z[i] = when(m, (oz + t * dz) - cz, hit.Ng_z[i]);
    hit.u[i] = when(m, 0.f, hit.u[i]);
    hit.v[i] = when(m, 0.f, hit.v[i]);
    hit.primID[i] = when(m, ids.prim, hit.primID[i]);
    hit.geomID[i] = when(m, ids.geom, hit.geomID[i]);
    hit.instID[0][i] = when(m, ids.inst, hit.instID[0][i]);
  }
}

template <class RayK, bool kMoving>
[[gnu::always_inline]] inline void occluded_lanes(const SphereLanes& s,
                                                  const int* __restrict valid,
                                                  RayK* __restrict ray) {
  constexpr int kN = sizeof(ray->tfar) / sizeof(float);
  for (int i = 0; i < kN; ++i) {
    float cx, cy, cz;
    lane_center<kMoving>(s, ray->time[i], &cx, &cy, &cz);
    const float t = lane_intersect_sphere(cx, cy, cz, s.radius, ray->org_x[i], ray->org_y[i],
                                          ray->org_z[i], ray->dir_x[i], ray->dir_y[i],
                                          ray->dir_z[i], ray->tfar[i], 0);
    const Mask m = mask(valid[i] != 0) & mask(t > ray->tnear[i]);
    ray->tfar[i] = when(m, -kInfinity, ray->tfar[i]);
  }
}

// One function per width for the target clones; the motion test is made once, outside the loop.
template <class RayHitK>
[[gnu::always_inline]] inline void intersect_packet(const SphereLanes& s, const int* valid,
                                                    RayHitK* rh, UserHitIds ids) {
  if (s.moving)
    intersect_lanes<RayHitK, true>(s, valid, rh, ids);
  else
    intersect_lanes<RayHitK, false>(s, valid, rh, ids);
}
template <class RayK>
[[gnu::always_inline]] inline void occluded_packet(const SphereLanes& s, const int* valid,
                                                   RayK* ray) {
  if (s.moving)
    occluded_lanes<RayK, true>(s, valid, ray);
  else
    occluded_lanes<RayK, false>(s, valid, ray);
}
PENUMBRA_SIMD_CLONES
void intersect16(const SphereLanes& s, const int* __restrict valid, RTCRayHit16* __restrict rh,
                 UserHitIds ids) {
  intersect_packet(s, valid, rh, ids);
}
PENUMBRA_SIMD_CLONES
void intersect8(const SphereLanes& s, const int* __restrict valid, RTCRayHit8* __restrict rh,
                UserHitIds ids) {
  intersect_packet(s, valid, rh, ids);
}
PENUMBRA_SIMD_CLONES
void intersect4(const SphereLanes& s, const int* __restrict valid, RTCRayHit4* __restrict rh,
                UserHitIds ids) {
  intersect_packet(s, valid, rh, ids);
}
PENUMBRA_SIMD_CLONES
void occluded16(const SphereLanes& s, const int* __restrict valid, RTCRay16* __restrict ray) {
  occluded_packet(s, valid, ray);
}
PENUMBRA_SIMD_CLONES
void occluded8(const SphereLanes& s, const int* __restrict valid, RTCRay8* __restrict ray) {
  occluded_packet(s, valid, ray);
}
PENUMBRA_SIMD_CLONES
void occluded4(const SphereLanes& s, const int* __restrict valid, RTCRay4* __restrict ray) {
  occluded_packet(s, valid, ray);
}

}  // namespace

void sphere_intersect_fn(const RTCIntersectFunctionNArguments* args) {
  if (args->N == 1) return sphere_intersect_one<1>(args, 0);
  const auto& sphere = *static_cast<const Sphere*>(args->geometryUserPtr);
  const UserHitIds ids = user_hit_ids(args);
  // An RTCRayHitN of a width known here is that width's RTCRayHitK (embree3/rtcore_ray.h).
  switch (args->N) {
    case 16:
      return intersect16(sphere_lanes(sphere), args->valid,
                         reinterpret_cast<RTCRayHit16*>(args->rayhit), ids);
    case 8:
      return intersect8(sphere_lanes(sphere), args->valid,
                        reinterpret_cast<RTCRayHit8*>(args->rayhit), ids);
    case 4:
      return intersect4(sphere_lanes(sphere), args->valid,
                        reinterpret_cast<RTCRayHit4*>(args->rayhit), ids);
    default:
      for (unsigned i = 0; i < args->N; ++i) sphere_intersect_one<0>(args, i);
  }
}

void sphere_occluded_fn(const RTCOccludedFunctionNArguments* args) {
  if (args->N == 1) return sphere_occluded_one<1>(args, 0);
  const auto& sphere = *static_cast<const Sphere*>(args->geometryUserPtr);
  switch (args->N) {
    case 16:
      return occluded16(sphere_lanes(sphere), args->valid, reinterpret_cast<RTCRay16*>(args->ray));
    case 8:
      return occluded8(sphere_lanes(sphere), args->valid, reinterpret_cast<RTCRay8*>(args->ray));
    case 4:
      return occluded4(sphere_lanes(sphere), args->valid, reinterpret_cast<RTCRay4*>(args->ray));
    default:
      for (unsigned i = 0; i < args->N; ++i) sphere_occluded_one<0>(args, i);
  }
}

Sphere::Sphere(const SphereDesc& desc, const ShapeContext& ctx)
    : center_(desc.center + ctx.offset),
      radius_(desc.radius),
      area_(4.f * kPi * desc.radius * desc.radius),
      motion_(ctx.motion),
      need_uv_(ctx.need_uv),
      sample_uv_(ctx.sample_uv) {}

EmbreeGeometry Sphere::make_geometry(RTCDevice device) const {
  // User geometry: the exact quadratic motion path needs our own test.
  EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER));
  if (!geom) return geom;
  rtcSetGeometryUserPrimitiveCount(geom.get(), 1);
  rtcSetGeometryBoundsFunction(geom.get(), sphere_bounds_fn, nullptr);
  rtcSetGeometryIntersectFunction(geom.get(), sphere_intersect_fn);
  rtcSetGeometryOccludedFunction(geom.get(), sphere_occluded_fn);
  rtcSetGeometryUserData(geom.get(), const_cast<Sphere*>(this));
  rtcCommitGeometry(geom.get());
  return geom;
}

Bounds3 Sphere::bounds() const {
  const Bounds3 d = motion_.displacement_bounds();
  return Bounds3{center_ - vec3(radius_) + d.lo, center_ + vec3(radius_) + d.hi};
}

Bounds3 Sphere::embree_bounds() const {
  // One static box around the whole swept path over the shutter: Embree's linear motion of
  // boxes between time steps cannot contain a quadratic path in general. The radius is padded
  // by the rounding error of the intersection test.
  const Bounds3 d = motion_.displacement_bounds();
  const vec3 r(radius_ * (1.f + 4.f * gamma_bound(4)));
  return Bounds3{center_ + d.lo - r, center_ + d.hi + r};
}

void Sphere::hit_geometry(const Ray& ray, float t, uint32_t, const vec2&, SurfaceHit* hit) const {
  sphere_hit_geometry(center_at(ray.time), radius_, ray.origin + ray.direction * t, hit);
  // Two inverse trigonometric functions per hit: only when textures read the uv.
  if (need_uv_) hit->uv = sphere_uv(hit->ng);
}

void Sphere::surface_derivatives(float, SurfaceHit* hit) const {
  // Derivatives of centre + r (sin v pi cos u 2 pi, sin v pi sin u 2 pi, cos v pi), as Mitsuba 3's
  // sphere; at the poles, where phi is undefined, dp/dv is +x as there.
  const vec3 n = hit->ng;
  hit->dpdu = (2.f * kPi * radius_) * vec3(-n.y, n.x, 0.f);
  const float rd = std::sqrt(n.x * n.x + n.y * n.y);
  hit->dpdv = rd > 0.f ? (kPi * radius_) * vec3(n.z * n.x / rd, n.z * n.y / rd, -rd)
                       : (kPi * radius_) * vec3(1.f, 0.f, 0.f);
}

bool Sphere::sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const {
  *out = sample_sphere(center_at(time), radius_, ref, u);
  if (sample_uv_) out->uv = sphere_uv(out->n);
  return true;
}

float Sphere::pdf(const vec3& ref, const vec3& p, const vec3& n, float time) const {
  return sphere_pdf(center_at(time), radius_, ref, p, n);
}

float intersect_sphere(const vec3& center, float radius, const vec3& origin, const vec3& dir,
                       float t_max, bool take_equal) {
  const vec3 f = origin - center;
  const float b = -glm::dot(f, dir);
  const vec3 l = f + b * dir;  // closest approach of the line to the centre
  const float r2 = radius * radius;
  const float disc = r2 - glm::dot(l, l);
  if (disc < 0.f) return -1.f;
  const float c = glm::dot(f, f) - r2;
  const float q = b + std::copysign(std::sqrt(disc), b);
  float t0 = q != 0.f ? c / q : 0.f;
  float t1 = q;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > 0.f && (t0 < t_max || (take_equal && t0 == t_max))) return t0;
  if (t1 > 0.f && (t1 < t_max || (take_equal && t1 == t_max))) return t1;
  return -1.f;
}

vec2 sphere_uv(const vec3& n) {
  float phi = std::atan2(n.y, n.x);
  if (phi < 0.f) phi += 2.f * kPi;
  return vec2(phi * kInv2Pi, std::acos(std::clamp(n.z, -1.f, 1.f)) * kInvPi);
}

void sphere_hit_geometry(const vec3& center, float radius, const vec3& p_approx, SurfaceHit* hit) {
  vec3 d = p_approx - center;
  const float len = glm::length(d);
  const vec3 n = len > 0.f ? d / len : vec3(0.f, 0.f, 1.f);
  hit->p = center + n * radius;
  // Error of centre + radius*n after re-projection (pbrt-v4 eq. 6.16 bounds the re-projected
  // point by gamma(5)|p| about the centre); the addition of the centre adds gamma(1)|p|.
  hit->p_error = gamma_bound(6) * (abs_components(center) + abs_components(n * radius));
  hit->ng = n;
  hit->ns = n;
}

ShapeSample sample_sphere(const vec3& center, float radius, const vec3& ref, const vec2& u) {
  ShapeSample s;
  float p[3], n[3], e[3];
  sphere_solid_angle_sample(center.x, center.y, center.z, radius, ref.x, ref.y, ref.z, u.x, u.y, p, n,
                            e, &s.pdf);
  s.p = vec3(p[0], p[1], p[2]);
  s.n = vec3(n[0], n[1], n[2]);
  s.p_error = vec3(e[0], e[1], e[2]);
  return s;
}

float sphere_pdf(const vec3& center, float radius, const vec3& ref, const vec3& p, const vec3& n) {
  const vec3 to_center = center - ref;
  const float dc2 = glm::dot(to_center, to_center);
  const float r2 = radius * radius;
  if (dc2 <= r2 * 1.0001f) return area_to_solid_angle(ref, p, n, 4.f * kPi * r2);
  const float sin2_max = r2 / dc2;
  const float one_minus_cos_max =
      sin2_max < 1e-3f ? sin2_max * 0.5f + sin2_max * sin2_max / 8.f : 1.f - safe_sqrt(1.f - sin2_max);
  return 1.f / (2.f * kPi * one_minus_cos_max);
}

}  // namespace penumbra
