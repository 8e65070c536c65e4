#include "renderer/shapes/triangle_mesh.h"

#include <algorithm>

#include "renderer/core/frame.h"
#include "renderer/embree/ray_access.h"
#include "renderer/sampling/sampling.h"
#include "renderer/textures/texture.h"

namespace penumbra {
namespace {

// ---- Embree's robust (watertight) test, with the sign of t settled exactly ----
//
// Embree's default triangle test (Moeller-Trumbore on precomputed edges) is not watertight:
// shadow rays slip through edges two triangles share (tests/stress LightLeak).
// RTC_SCENE_FLAG_ROBUST switches to its Pluecker test, whose edge functions are computed the same
// way for both triangles of an edge (Embree kernels/geometry/triangle_intersector_pluecker.h).
// Neither test bounds the rounding error of its own t as pbrt-v4's does (it rejects t <= deltaT,
// section 6.8.7), and our spawn offsets (core/ray.h, pbrt-v4 section 6.8.6) cover only the hit
// point's error, so a ray can re-hit the triangle it leaves: the robust test accepts t == tnear
// == 0 for a ray starting exactly on the plane (an exact hit point has a zero offset), and
// Embree's plane distance carries an error of order eps times the distance of the triangle's
// first vertex from the ray origin (docs/design-notes.md has the measurements).
// So every triangle hit passes this test (here as Embree's geometry filter, or, for meshes the
// scene checks after traversal, through scene/exact_t_check.h), which re-evaluates the sign of
// t = ((p0 - o) . n) / (d . n) in double precision from the same float vertices hit points are
// rebuilt from and keeps the hit only if t > 0. Products of floats are exact to 2^-53 in
// double, so the sign is right far below any spawn offset; a hit with t > 0 is never dropped,
// so watertightness stays.
inline void filter_triangle_hit(const RTCFilterFunctionNArguments* args, unsigned n, unsigned i) {
  if (args->valid[i] == 0) return;
  const auto& mesh = *static_cast<const TriangleMesh*>(args->geometryUserPtr);
  if (!mesh.ahead_of_ray(RTCHitN_primID(args->hit, n, i), embree_ray_origin(args->ray, n, i),
                         embree_ray_direction(args->ray, n, i), RTCRayN_time(args->ray, n, i)))
    args->valid[i] = 0;
  // A cutout's holes let every ray through, camera and shadow rays alike (glTF alpha MASK).
  else if (mesh.has_cutout() &&
           !mesh.solid_at(RTCHitN_primID(args->hit, n, i), RTCHitN_u(args->hit, n, i),
                          RTCHitN_v(args->hit, n, i)))
    args->valid[i] = 0;
}

void triangle_filter_fn(const RTCFilterFunctionNArguments* args) {
  for_each_filter_lane(args, [args](unsigned n, unsigned i) { filter_triangle_hit(args, n, i); });
}

// Vertex buffers at evenly spread shutter instants. Linear interpolation of the quadratic path
// between steps deviates by at most |a| dt^2 / 8; keep that below 1e-4 of the distance to the
// camera (about a seventh of a pixel at 1000 pixels over a 40 degree view), at most Embree's 129.
int motion_time_steps(const Motion& motion, float span, float camera_distance) {
  if (motion.is_static() || span <= 0.f) return 1;
  const float a = glm::length(motion.acceleration);
  if (a == 0.f) return 2;
  const float tolerance = std::max(1e-4f * camera_distance, 1e-12f);
  const float intervals = std::ceil(span * std::sqrt(a / (8.f * tolerance)));
  return int(std::clamp(intervals, 1.f, 128.f)) + 1;
}

// The point b0 p0 + b1 p1 + b2 p2 and its error bound: pbrt-v4 section 6.8.4 bounds the error of
// the barycentric sum by gamma(7).
[[gnu::always_inline]] inline void barycentric_point(const vec3& p0, const vec3& p1,
                                                     const vec3& p2, float b0, float b1, float b2,
                                                     vec3* p, vec3* error) {
  const vec3 t0 = b0 * p0, t1 = b1 * p1, t2 = b2 * p2;
  *p = t0 + t1 + t2;
  *error = gamma_bound(7) * (abs_components(t0) + abs_components(t1) + abs_components(t2));
}

// The unit normal (p1 - p0) x (p2 - p0), +z for a degenerate triangle.
[[gnu::always_inline]] inline vec3 unit_face_normal(const vec3& p0, const vec3& p1, const vec3& p2) {
  const vec3 ng = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(ng);
  return len > 0.f ? ng / len : vec3(0.f, 0.f, 1.f);
}

float triangle_area(const vec3& a, const vec3& b, const vec3& c) {
  return 0.5f * glm::length(glm::cross(b - a, c - a));
}

}  // namespace

TriangleMesh::TriangleMesh(const MeshDesc& desc, const ShapeContext& ctx)
    : alpha_(ctx.alpha),
      alpha_factor_(ctx.alpha_factor),
      alpha_cutoff_(ctx.alpha_cutoff),
      positions_(desc.positions),
      indices_(desc.indices),
      normals_(desc.normals),
      uvs_(desc.uvs),
      need_uv_(ctx.need_uv) {
  for (vec3& p : positions_) p += ctx.offset;
  const size_t n = indices_.size() / 3;
  std::vector<float> areas(n);
  double total = 0.0;
  for (size_t t = 0; t < n; ++t) {
    const vec3 &a = positions_[indices_[3 * t]], &b = positions_[indices_[3 * t + 1]],
               &c = positions_[indices_[3 * t + 2]];
    areas[t] = triangle_area(a, b, c);
    total += areas[t];
    max_edge_ = std::max({max_edge_, glm::length(b - a), glm::length(c - b), glm::length(a - c)});
  }
  area_ = float(total);
  if (ctx.emissive && n > 0) {
    triangle_cdf_.resize(n);
    double acc = 0.0;
    for (size_t t = 0; t < n; ++t) {
      acc += areas[t];
      triangle_cdf_[t] = float(acc / total);
    }
    triangle_cdf_.back() = 1.f;
  }

  Bounds3 own;
  for (const vec3& p : positions_) own.extend(p);
  const Bounds3 d = ctx.motion.displacement_bounds();
  bounds_ = Bounds3{own.lo + d.lo, own.hi + d.hi};

  const vec3 nearest = glm::clamp(ctx.camera_position, bounds_.lo, bounds_.hi);
  const float camera_distance = std::max(glm::length(nearest - ctx.camera_position),
                                         1e-3f * glm::length(own.hi - own.lo));
  time_steps_ = motion_time_steps(ctx.motion.motion, ctx.motion.shutter_span, camera_distance);
  if (time_steps_ > 1) {
    step_displacement_.resize(time_steps_);
    for (int k = 0; k < time_steps_; ++k)
      step_displacement_[k] = ctx.motion.motion.displacement(
          ctx.motion.shutter_open + ctx.motion.shutter_span * float(k) / float(time_steps_ - 1));
  } else {
    face_normals_.resize(n);
    for (size_t t = 0; t < n; ++t)
      face_normals_[t] = unit_face_normal(positions_[indices_[3 * t]], positions_[indices_[3 * t + 1]],
                                          positions_[indices_[3 * t + 2]]);
  }
}

DirectionCone TriangleMesh::normal_cone() const {
  const size_t n = triangle_count();
  const auto face = [&](size_t t) {
    const vec3 p0 = positions_[indices_[3 * t]], p1 = positions_[indices_[3 * t + 1]],
               p2 = positions_[indices_[3 * t + 2]];
    return glm::cross(p1 - p0, p2 - p0);  // area-weighted: twice the area, along the normal
  };
  vec3 sum(0.f);
  for (size_t t = 0; t < n; ++t) sum += face(t);
  const float len = glm::length(sum);
  if (!(len > 0.f) || !std::isfinite(len)) return DirectionCone::whole_sphere();
  DirectionCone cone;
  cone.axis = sum / len;
  float cos_theta = 1.f;
  for (size_t t = 0; t < n; ++t) {
    const vec3 f = face(t);
    const float l = glm::length(f);
    if (l > 0.f && std::isfinite(l)) cos_theta = std::min(cos_theta, glm::dot(cone.axis, f) / l);
  }
  // A flat mesh (a quad, a panel) points one way: exactly, so that the light tree sees points
  // behind its plane as out of reach; otherwise a little wider than the farthest normal.
  cone.cos_theta = cos_theta >= 1.f - 1e-6f ? 1.f : std::max(-1.f, cos_theta - 1e-4f);
  return cone;
}

vec3 TriangleMesh::interpolated_displacement(float time) const {
  // Embree interpolates vertex buffers linearly between evenly spread time steps.
  const float f = std::clamp(time, 0.f, 1.f) * float(time_steps_ - 1);
  const int i = std::min(int(f), time_steps_ - 2);
  const float w = f - float(i);
  return glm::mix(step_displacement_[i], step_displacement_[i + 1], w);
}

bool TriangleMesh::trace_as_parallelograms() {
  if (moving() || has_cutout() || !triangle_cdf_.empty() ||
      triangle_count() > 2 * kMaxFacePairs)
    return false;
  face_pairs_ = pair_into_parallelograms(positions_, indices_);
  return !face_pairs_.shapes.empty();
}

EmbreeGeometry TriangleMesh::make_geometry(RTCDevice device) const {
  if (!face_pairs_.shapes.empty())
    return make_parallelogram_geometry(device, face_pairs_.shapes.data(), face_pairs_.shapes.size());
  EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE));
  if (!geom) return geom;
  if (filter_in_traversal()) {
    rtcSetGeometryIntersectFilterFunction(geom.get(), triangle_filter_fn);
    rtcSetGeometryOccludedFilterFunction(geom.get(), triangle_filter_fn);
  }
  rtcSetGeometryTimeStepCount(geom.get(), unsigned(time_steps_));
  static_assert(sizeof(vec3) == 12, "vertex layout");
  for (int k = 0; k < time_steps_; ++k) {
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom.get(), RTC_BUFFER_TYPE_VERTEX,
                                                          unsigned(k), RTC_FORMAT_FLOAT3,
                                                          sizeof(float) * 3, positions_.size()));
    if (!v) return EmbreeGeometry();  // the scene build reports Embree's error
    const vec3 d = time_steps_ > 1 ? step_displacement_[k] : vec3(0.f);
    for (size_t p = 0; p < positions_.size(); ++p) {
      const vec3 q = positions_[p] + d;
      v[3 * p] = q.x;
      v[3 * p + 1] = q.y;
      v[3 * p + 2] = q.z;
    }
  }
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(uint32_t) * 3, indices_.size() / 3));
  if (!idx) return EmbreeGeometry();
  std::copy(indices_.begin(), indices_.end(), idx);
  rtcSetGeometryUserData(geom.get(), const_cast<TriangleMesh*>(this));
  rtcCommitGeometry(geom.get());
  return geom;
}

void TriangleMesh::hit_geometry(const Ray& ray, float, uint32_t prim, const vec2& uv,
                                SurfaceHit* hit) const {
  if (!face_pairs_.shapes.empty()) return face_pair_hit(prim, uv, hit);
  const uint32_t* tri = &indices_[size_t(prim) * 3];
  vec3 p0 = positions_[tri[0]], p1 = positions_[tri[1]], p2 = positions_[tri[2]];
  vec3 ng;
  if (time_steps_ > 1) {  // static meshes skip adding a zero displacement
    const vec3 disp = interpolated_displacement(ray.time);
    p0 += disp;
    p1 += disp;
    p2 += disp;
    ng = unit_face_normal(p0, p1, p2);
  } else {
    ng = face_normals_[prim];
  }
  const float b1 = uv.x, b2 = uv.y, b0 = 1.f - b1 - b2;
  barycentric_point(p0, p1, p2, b0, b1, b2, &hit->p, &hit->p_error);
  hit->ng = ng;
  interpolate(tri, b0, b1, b2, hit);
}

void TriangleMesh::face_pair_hit(uint32_t pair, const vec2& st, SurfaceHit* hit) const {
  // The point on the parallelogram the test met (Quad::hit_geometry), in the triangle of the
  // pair it lies in, which surface_derivatives reads through hit->primitive.
  const Parallelogram& q = face_pairs_.shapes[pair];
  parallelogram_point(q.origin, q.u, q.v, st.x, st.y, &hit->p, &hit->p_error);
  float b[3];
  const uint32_t prim = 2 * pair + uint32_t(face_pairs_.slots[pair].locate(st.x, st.y, b));
  hit->primitive = prim;
  hit->ng = face_normals_[prim];
  interpolate(&indices_[size_t(prim) * 3], b[0], b[1], b[2], hit);
}

void TriangleMesh::interpolate(const uint32_t* tri, float b0, float b1, float b2,
                               SurfaceHit* hit) const {
  const vec3 ng = hit->ng;
  if (need_uv_) hit->uv = uv_at(tri, b0, b1, b2);
  hit->ns = ng;
  if (!normals_.empty()) {
    vec3 ns = b0 * normals_[tri[0]] + b1 * normals_[tri[1]] + b2 * normals_[tri[2]];
    const float ls = glm::length(ns);
    if (ls > 0.f && std::isfinite(ls)) {
      ns /= ls;
      hit->ns = glm::dot(ns, ng) < 0.f ? -ns : ns;
    }
  }
}

bool TriangleMesh::solid_at(uint32_t prim, float b1, float b2) const {
  const uint32_t* tri = &indices_[size_t(prim) * 3];
  TextureQuery q;
  q.uv = uv_at(tri, 1.f - b1 - b2, b1, b2);
  // glTF 2.0 section 3.9.4: opaque where alpha >= alphaCutoff, fully transparent elsewhere.
  return alpha_factor_ * alpha_->eval(q) >= alpha_cutoff_;
}

void TriangleMesh::surface_derivatives(float, SurfaceHit* hit) const {
  // pbrt-v4 Triangle::InteractionFromIntersection: solve
  //   [p0 - p2, p1 - p2] = [dp/du, dp/dv] [uv0 - uv2, uv1 - uv2]
  // for the two derivatives (motion is a translation, so edges need no displacement).
  const uint32_t* tri = &indices_[size_t(hit->primitive) * 3];
  const vec3 p0 = positions_[tri[0]], p1 = positions_[tri[1]], p2 = positions_[tri[2]];
  const vec2 uv0 = uv_at(tri, 1.f, 0.f, 0.f), uv1 = uv_at(tri, 0.f, 1.f, 0.f),
             uv2 = uv_at(tri, 0.f, 0.f, 1.f);
  const vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
  const vec3 dp02 = p0 - p2, dp12 = p1 - p2;
  const float det = duv02.x * duv12.y - duv02.y * duv12.x;
  const bool degenerate = !(std::abs(det) >= 1e-9f);
  if (!degenerate) {
    const float inv = 1.f / det;
    hit->dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
    hit->dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
  }
  // Without a usable parametrisation (uvs that do not span the triangle) any tangent frame of
  // the geometric normal will do.
  if (degenerate || !(glm::length(glm::cross(hit->dpdu, hit->dpdv)) > 0.f) || !is_finite(hit->dpdu) ||
      !is_finite(hit->dpdv)) {
    const Frame f(hit->ng);
    hit->dpdu = f.s;
    hit->dpdv = f.t;
  }
}

bool TriangleMesh::sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const {
  // Pick a triangle by area with u.x, reuse what is left of u.x inside its interval.
  const auto it = std::upper_bound(triangle_cdf_.begin(), triangle_cdf_.end(), u.x);
  const size_t t = std::min<size_t>(it - triangle_cdf_.begin(), triangle_cdf_.size() - 1);
  const float lo = t > 0 ? triangle_cdf_[t - 1] : 0.f;
  const float width = triangle_cdf_[t] - lo;
  const float ux = width > 0.f ? std::min((u.x - lo) / width, kOneMinusEpsilon) : 0.5f;
  const vec2 b = square_to_triangle(vec2(ux, u.y));
  const vec3 disp = displacement_at(time);
  const uint32_t* tri = &indices_[3 * t];
  const vec3 p0 = positions_[tri[0]] + disp, p1 = positions_[tri[1]] + disp,
             p2 = positions_[tri[2]] + disp;
  barycentric_point(p0, p1, p2, 1.f - b.x - b.y, b.x, b.y, &out->p, &out->p_error);
  out->uv = uv_at(tri, 1.f - b.x - b.y, b.x, b.y);
  const vec3 ng = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(ng);
  if (!(len > 0.f)) return false;
  out->n = ng / len;
  out->pdf = area_to_solid_angle(ref, out->p, out->n, area_);
  return true;
}

float TriangleMesh::pdf(const vec3& ref, const vec3& p, const vec3& n, float) const {
  return area_to_solid_angle(ref, p, n, area_);
}

}  // namespace penumbra
