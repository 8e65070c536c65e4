#include "renderer/shapes/instance.h"

#include <algorithm>
#include <cmath>

#include "renderer/shapes/shape.h"

namespace penumbra {
namespace {

glm::mat3 abs_matrix(const glm::mat3& m) {
  return glm::mat3(glm::abs(m[0]), glm::abs(m[1]), glm::abs(m[2]));
}

double infinity_norm(const glm::dmat3& m) {  // largest absolute row sum
  double n = 0.0;
  for (int r = 0; r < 3; ++r)
    n = std::max(n, std::abs(m[0][r]) + std::abs(m[1][r]) + std::abs(m[2][r]));
  return n;
}

vec3 unit_or(const vec3& v, const vec3& fallback) {
  const float len = glm::length(v);
  return len > 0.f && std::isfinite(len) ? v / len : fallback;
}

}  // namespace

Instance::Instance(const Shape& shape, uint32_t object, const InstanceTransform& transform)
    : shape_(&shape), linear_(transform.linear), translation_(transform.translation), object_(object) {
  // Derived matrices in double from the float matrix Embree is given, then rounded once.
  const glm::dmat3 a(linear_);
  const glm::dmat3 inverse = glm::inverse(a);
  inverse_ = glm::mat3(inverse);
  inverse_translation_ = vec3(-(inverse * glm::dvec3(translation_)));
  // Columns a1 x a2, a2 x a0, a0 x a1: det(A) * A^-T, the map of the normals of triangles whose
  // vertices are mapped by A (cross(A e1, A e2) = cof(A) cross(e1, e2)).
  cofactor_ = glm::mat3(glm::mat3(glm::dmat3(glm::cross(a[1], a[2]), glm::cross(a[2], a[0]),
                                             glm::cross(a[0], a[1]))));
  // Embree maps rays into the copy with its own single-precision inverse of linear_ (adjugate
  // over determinant). A normwise bound on the error of a computed inverse is a small multiple
  // of eps times the condition number times its size (Higham 2002, section 14.1); gamma(8) is
  // that multiple with room to spare, and it is applied to every entry.
  const double condition = infinity_norm(a) * infinity_norm(inverse);
  double largest = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) largest = std::max(largest, std::abs(inverse[c][r]));
  inverse_slack_ = float(double(gamma_bound(8)) * condition * largest);
}

EmbreeGeometry Instance::make_geometry(RTCDevice device, RTCScene child) const {
  EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE));
  if (!geom) return geom;
  rtcSetGeometryInstancedScene(geom.get(), child);
  float m[12];  // RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR: the three columns of linear, then translation
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m[3 * c + r] = linear_[c][r];
  for (int r = 0; r < 3; ++r) m[9 + r] = translation_[r];
  rtcSetGeometryTransform(geom.get(), 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
  rtcCommitGeometry(geom.get());
  return geom;
}

Bounds3 Instance::bounds() const {
  const Bounds3 b = shape_->bounds();
  Bounds3 out;
  for (int k = 0; k < 8; ++k) {
    const vec3 corner((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y,
                      (k & 4) ? b.hi.z : b.lo.z);
    out.extend(linear_ * corner + translation_);
  }
  return out;
}

void Instance::hit_geometry(const Ray& world_ray, float t, uint32_t prim, const vec2& uv,
                            SurfaceHit* hit) const {
  Ray local = world_ray;
  local.origin = inverse_ * world_ray.origin + inverse_translation_;
  local.direction = inverse_ * world_ray.direction;  // not unit: the parameter t is shared
  SurfaceHit h;
  h.primitive = prim;
  shape_->hit_geometry(local, t, prim, uv, &h);
  hit->primitive = h.primitive;  // a mesh traced as parallelograms names the triangle hit

  // pbrt-v4's Transform applied to a point with an error interval: three products and three
  // sums per component, each rounding once, plus the carried error grown by (1 + gamma(3)).
  constexpr float g3 = gamma_bound(3);
  const glm::mat3 abs_a = abs_matrix(linear_);
  const vec3 p = linear_ * h.p + translation_;
  vec3 error = (1.f + g3) * (abs_a * h.p_error) + g3 * (abs_a * glm::abs(h.p) + glm::abs(translation_));
  // A ray spawned here is mapped back into the copy by Embree, with a rounding error pbrt-v4
  // does not have (it transforms rays itself and moves their origins to the edge of the error
  // interval). That error, in object space, is bounded by gamma(3) and the inverse's own error
  // times the size of the point and translation; mapped to world space by |A| it widens the
  // interval, so the spawn offset (offset_ray_origin) also covers it.
  const vec3 size = glm::abs(p) + glm::abs(translation_);
  const vec3 local_slack = g3 * (abs_matrix(inverse_) * size) +
                           vec3(inverse_slack_ * (size.x + size.y + size.z));
  error += abs_a * local_slack;
  // The bound's own arithmetic rounds down at most a few ulps: one more gamma covers it.
  hit->p = p;
  hit->p_error = error * (1.f + g3);

  hit->ng = unit_or(cofactor_ * h.ng, h.ng);
  vec3 ns = unit_or(cofactor_ * h.ns, hit->ng);
  hit->ns = glm::dot(ns, hit->ng) < 0.f ? -ns : ns;
  hit->uv = h.uv;
}

void Instance::surface_derivatives(float time, SurfaceHit* hit) const {
  // The mesh reads the primitive, and the geometric normal where its uvs do not span the
  // triangle (any tangent frame of it will do): normals map back by the transpose of linear_,
  // up to a scale (cofactor_ = det * inverse transpose).
  SurfaceHit local = *hit;
  local.ng = unit_or(glm::transpose(linear_) * hit->ng, hit->ng);
  if (glm::determinant(linear_) < 0.f) local.ng = -local.ng;
  shape_->surface_derivatives(time, &local);
  hit->dpdu = linear_ * local.dpdu;
  hit->dpdv = linear_ * local.dpdv;
}

EmbreeScene make_instanced_scene(RTCDevice device, RTCGeometry geometry, RTCSceneFlags flags) {
  EmbreeScene scene(rtcNewScene(device));
  if (!scene) return scene;
  // As the top-level scene (scene_builder.cpp): the triangles' watertight test and filter
  // behave the same inside a copy.
  rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneFlags(scene.get(), flags);
  rtcAttachGeometryByID(scene.get(), geometry, 0);
  rtcCommitScene(scene.get());
  return scene;
}

}  // namespace penumbra
