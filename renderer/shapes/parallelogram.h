#pragma once
// A static quad's own ray test, for Embree user geometry: the plane o + s u + t v met at
// ((o - ray origin) . n) / (d . n), then its (s, t) inside [0, 1]^2, as Mitsuba 3's rectangle.
// Embree's robust test on the quad's two triangles costs more per ray (two triangles in the
// BVH, the watertight edge functions); docs/performance.md, "Quads as parallelograms".
//
// Re-hits of the surface a ray leaves: the sign of t is decided in double precision from the
// same float corner and edges hit points are rebuilt from (as TriangleMesh::ahead_of_ray), so a
// spawned ray, whose origin lies beyond the hit point's error bound, never meets its own quad
// again. Seams: (s, t) may exceed [0, 1] by kEdgeTolerance, so two quads sharing an edge
// overlap by that much instead of leaving a crack of rounding width between them. Ties: a hit
// at exactly the t of the ray's current hit replaces it when its (instance, geometry) ids are
// lower, so coincident quads give a ray the same hit in a packet as alone.
#include <embree3/rtcore.h>

#include "renderer/core/bounds.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

struct Parallelogram {
  // s and t may leave [0, 1] by this much (relative to the edge): it covers their rounding for
  // rays up to about 100 edge lengths long.
  static constexpr float kEdgeTolerance = 1e-5f;

  explicit Parallelogram(const QuadDesc& q);

  // The axis its plane is perpendicular to (u and v have no component along it), or -1.
  int flat_axis() const;
  // Gives a box of zero thickness along its flat axis some (below). Embree skips a box whose
  // entry distance it computes at or past the ray's current hit, and a flat box's entry
  // distance is the hit's own t: after a hit on a quad in the same plane at the same t (a
  // duplicate, or a neighbour at their shared edge) it may skip this one, and whether it does
  // depends on the traversal order, which differs between packets and single rays; the tie rule
  // of the callbacks (lowest ids win) only works on hits it is shown. Flat boxes trace faster
  // (thickening every quad cost cornell 7%), so the scene build thickens only quads that share
  // their axis plane with another (scene_builder.cpp).
  void thicken();

  vec3 origin, u, v;
  dvec3 normal;      // cross(u, v) in double: exact products of the float edges
  vec3 du, dv;       // s = (p - origin) . du, t = (p - origin) . dv for p in the plane
  Bounds3 bounds;    // padded by the tolerance and the test's rounding
};

// The Embree callbacks of a parallelogram's user geometry (user data: the Parallelogram). A hit
// reports (s, t) as Embree's (u, v); declared for tests, which compare packets with single rays.
void parallelogram_bounds_fn(const RTCBoundsFunctionArguments* args);
void parallelogram_intersect_fn(const RTCIntersectFunctionNArguments* args);
void parallelogram_occluded_fn(const RTCOccludedFunctionNArguments* args);

}  // namespace penumbra
