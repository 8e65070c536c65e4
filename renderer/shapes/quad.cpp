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
      normal_(glm::normalize(glm::cross(quad_.u, quad_.v))) {
  set_area(glm::length(glm::cross(desc.u, desc.v)));
}

bool Quad::sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const {
  const vec3 su = u.x * quad_.u, sv = u.y * quad_.v;
  const vec3 o = moving() ? quad_.origin + displacement_at(time) : quad_.origin;
  out->p = o + su + sv;
  // Three products and two sums per coordinate, rounded once each (pbrt-v4 section 6.8.1).
  out->p_error = gamma_bound(6) * (abs_components(o) + abs_components(su) + abs_components(sv));
  out->n = normal_;
  out->uv = u;
  out->pdf = area_to_solid_angle(ref, out->p, out->n, area());
  return true;
}

}  // namespace penumbra
