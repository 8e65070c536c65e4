#pragma once
// The exact-t test of triangle hits (TriangleMesh::ahead_of_ray: the sign of t in double, which
// rejects a re-hit of the surface a ray leaves) run after Embree's traversal instead of inside
// it. A "plain" mesh (no cutout, no copies) registers no Embree geometry filter, so Embree uses
// its filter-free kernels; Scene::intersect checks only the closest hit Embree returns, and a
// hit that fails is traced again, one ray, with a context filter that runs the test on every
// candidate. The filter only removes candidates, so an unfiltered closest hit that passes is
// the filtered closest hit, provided the closest hit is unique. Occlusion queries use the
// context filter from the start (a blocked shadow ray is common, and a second traversal costs
// more than the filter calls an occlusion query makes before it stops); the filter settles most
// candidates without the exact test, where a bound on Embree's rounding says the sign of its t
// cannot be wrong (embree_hit_certainly_ahead).
//
// The closest hit is not unique on exactly coincident triangles, and Embree's filter-free
// packet kernels break those ties differently from its single-ray ones (a path through two
// identical glass boxes would enter one and leave through the other). So a scene with any two
// coincident triangles keeps the geometry filter on every mesh (has_coincident_triangles).
// docs/performance.md, "Exact-t check after traversal", has the measurements.
#include <embree3/rtcore.h>

#include <cstdint>
#include <type_traits>
#include <vector>

#include "renderer/core/bounds.h"
#include "renderer/core/ray.h"
#include "renderer/shapes/triangle_mesh.h"

namespace penumbra {

class ExactTCheck;

// An intersect context that carries the check to its filter (Embree hands the filter the
// pointer it was given, so the check travels behind Embree's own fields).
struct ExactTContext {
  RTCIntersectContext embree;  // first: the filter casts Embree's pointer back
  const ExactTCheck* check;
};
static_assert(std::is_standard_layout_v<ExactTContext>);

class ExactTCheck {
 public:
  // Off: every mesh filters in traversal, nothing is checked after it.
  ExactTCheck() = default;
  // plain[id] is the mesh of Embree geometry id `id` if it is checked here (it registered no
  // geometry filter), else nullptr.
  explicit ExactTCheck(std::vector<const TriangleMesh*> plain) : plain_(std::move(plain)) {}

  bool enabled() const { return !plain_.empty(); }

  // Whether a closest hit Embree reported is a re-hit at t <= 0 of a plain mesh. Copies
  // (inst_id valid) and other geometry filtered in traversal.
  bool rejects(uint32_t geom_id, uint32_t inst_id, uint32_t prim, const vec3& origin,
               const vec3& direction, float time) const {
    const TriangleMesh* mesh = plain_mesh(geom_id, inst_id);
    return mesh && !mesh->ahead_of_ray(prim, origin, direction, time);
  }

  // A context with `flags` whose filter applies the test to every candidate on a plain mesh
  // (no filter when the check is off: the geometry filters do it).
  ExactTContext context(RTCIntersectContextFlags flags) const;

  const TriangleMesh* plain_mesh(uint32_t geom_id, uint32_t inst_id) const {
    if (inst_id != RTC_INVALID_GEOMETRY_ID || geom_id >= plain_.size()) return nullptr;
    return plain_[geom_id];
  }

 private:
  std::vector<const TriangleMesh*> plain_;
};

// Whether a candidate hit Embree's robust triangle test reports on a static triangle, at t along
// the ray (o, d) with Embree's unnormalised geometric normal ng, has t > 0 in exact arithmetic
// for certain, so the exact test (TriangleMesh::ahead_of_ray, three vertex loads and a double
// cross product) can be skipped; false means "do the exact test", never "reject".
// `box` holds the triangle's vertices, `max_edge` bounds its edges.
//
// Why it holds. Embree's Pluecker test translates the vertices to the ray origin, v = V - o
// (each coordinate rounded: |dv| <= u |v|, u = 2^-24), takes the edges between those and the
// normal Ng from two edges, then T = dot(v0, Ng) and den = dot(Ng, d), and t = T / den. With
// R >= |v| for every vertex and L >= every edge, the rounded edges are off by at most
// u (2 R + L) and Ng (each component a difference of two products of edge components) by
// u (4 R + 5 L) L, so T is off by at most u R ((4 R + 5 L) L + 4 |Ng|) (v0's rounding, Ng's,
// the dot product's) and den by u |d| ((4 R + 5 L) L + 3 |Ng|): within E_T = u R A and
// E_den = u |d| A, where A = 7 (R + L) L + 5 |Ng|. Embree keeps a candidate whose T and den have
// the same sign; if the exact t is <= 0 one of them has the wrong sign (or T is exactly 0), so
// |T| <= E_T or |den| <= E_den as Embree computed them; with T = t den, den <= u A max(|d|, R / t).
// The test asks for 32 times more. It fails safe: NaN, infinities and underflow all give false.
// Grazing rays and hits close to the origin relative to R fail it and take the exact test.
inline bool embree_hit_certainly_ahead(const vec3& o, const vec3& d, float t, const vec3& ng,
                                       const Bounds3& box, float max_edge) {
  constexpr double kMargin = 16.0, kUlp = 0x1p-24;
  const dvec3 centre = 0.5 * (dvec3(box.lo) + dvec3(box.hi));
  const double reach = glm::length(dvec3(o) - centre) + 0.5 * glm::length(dvec3(box.hi) - dvec3(box.lo));
  const dvec3 n(ng);
  const double den = std::abs(glm::dot(n, dvec3(d)));
  const double a = 7.0 * (reach + double(max_edge)) * double(max_edge) + 5.0 * glm::length(n);
  const double bound = 2.0 * kMargin * kUlp * a * std::max(glm::length(dvec3(d)), reach / double(t));
  return t > 0.f && den > bound;
}

// The closest hit along `ray` with the test on every candidate: one ray through the context
// filter, for a ray whose unfiltered closest hit the check rejected.
RTCRayHit exact_t_retrace(RTCScene scene, const ExactTCheck& check, const Ray& ray);

// Whether two triangles of `meshes` (within one mesh or across) have the same three vertices as
// a set, compared bit for bit (-0 as +0) at every Embree time step. Expected O(n) (a hash set
// of the triangles); meshes with different numbers of time steps never match (a moving mesh
// coincides with another one only if it moves alike).
bool has_coincident_triangles(const std::vector<const TriangleMesh*>& meshes);

}  // namespace penumbra
