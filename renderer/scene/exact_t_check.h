#pragma once
// The exact-t test of triangle hits (TriangleMesh::ahead_of_ray: the sign of t in double, which
// rejects a re-hit of the surface a ray leaves) run after Embree's traversal instead of inside
// it. A "plain" mesh (no cutout, no copies) registers no Embree geometry filter, so Embree uses
// its filter-free kernels; Scene::intersect checks only the closest hit Embree returns, and a
// hit that fails is traced again, one ray, with a context filter that runs the test on every
// candidate. The filter only removes candidates, so an unfiltered closest hit that passes is
// the filtered closest hit, provided the closest hit is unique. Occlusion queries use the
// context filter from the start (a blocked shadow ray is common, and a second traversal costs
// more than the filter calls an occlusion query makes before it stops).
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

// The closest hit along `ray` with the test on every candidate: one ray through the context
// filter, for a ray whose unfiltered closest hit the check rejected.
RTCRayHit exact_t_retrace(RTCScene scene, const ExactTCheck& check, const Ray& ray);

// Whether two triangles of `meshes` (within one mesh or across) have the same three vertices as
// a set, compared bit for bit (-0 as +0) at every Embree time step. Expected O(n) (a hash set
// of the triangles); meshes with different numbers of time steps never match (a moving mesh
// coincides with another one only if it moves alike).
bool has_coincident_triangles(const std::vector<const TriangleMesh*>& meshes);

}  // namespace penumbra
