#include "renderer/shapes/quad.h"

namespace penumbra {
namespace {

MeshDesc two_triangles(const QuadDesc& q) {
  const vec3 o = q.origin;
  // uv at o + s u + t v is (s, t).
  return MeshDesc{{o, o + q.u, o + q.u + q.v, o + q.v}, {0, 1, 2, 0, 2, 3}, {}, {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)}};
}

QuadDesc moved(QuadDesc q, const vec3& offset) {
  q.origin += offset;
  return q;
}

// The triangles get the moved corners and need no sampling table of their own.
ShapeContext triangles_context(ShapeContext ctx) {
  ctx.offset = vec3(0.f);
  ctx.emissive = false;
  return ctx;
}

}  // namespace

Quad::Quad(const QuadDesc& desc, const ShapeContext& ctx)
    : TriangleMesh(two_triangles(moved(desc, ctx.offset)), triangles_context(ctx)),
      quad_(moved(desc, ctx.offset)),
      normal_(glm::normalize(glm::cross(quad_.u, quad_.v))),
      test_(quad_),
      parallelogram_(!moving() && !has_cutout()) {
  set_area(glm::length(glm::cross(desc.u, desc.v)));
}

EmbreeGeometry Quad::make_geometry(RTCDevice device) const {
  if (!parallelogram_) return TriangleMesh::make_geometry(device);
  return make_parallelogram_geometry(device, &test_, 1);
}

void Quad::hit_geometry(const Ray& ray, float t, uint32_t prim, const vec2& uv,
                        SurfaceHit* hit) const {
  if (!parallelogram_) return TriangleMesh::hit_geometry(ray, t, prim, uv, hit);
  // Embree's (u, v) are the parallelogram's (s, t) (shapes/parallelogram.cpp).
  parallelogram_point(quad_.origin, quad_.u, quad_.v, uv.x, uv.y, &hit->p, &hit->p_error);
  hit->uv = uv;
  hit->ng = normal_;
  hit->ns = normal_;
}

void Quad::surface_derivatives(float time, SurfaceHit* hit) const {
  if (!parallelogram_) return TriangleMesh::surface_derivatives(time, hit);
  hit->dpdu = quad_.u;  // of o + s u + t v with uv = (s, t), as the triangles' solve gives
  hit->dpdv = quad_.v;
}

bool Quad::sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const {
  const vec3 o = moving() ? quad_.origin + displacement_at(time) : quad_.origin;
  parallelogram_point(o, quad_.u, quad_.v, u.x, u.y, &out->p, &out->p_error);
  out->n = normal_;
  out->uv = u;
  out->pdf = area_to_solid_angle(ref, out->p, out->n, area());
  return true;
}

}  // namespace penumbra
