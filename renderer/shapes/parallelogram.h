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
// at exactly the t of the ray's current hit replaces it when its (instance, geometry,
// primitive) ids are lower, so coincident quads give a ray the same hit in a packet as alone.
//
// One user geometry holds any number of them (a quad's one, the face pairs of a mesh traced as
// parallelograms, shapes/parallelogram_pairs.h), Embree's primitive id indexing the array.
#include <embree3/rtcore.h>

#include "renderer/core/bounds.h"
#include "renderer/core/ray.h"
#include "renderer/embree/handles.h"
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
  // (thickening every quad cost cornell 7%), so the scene build thickens only those that can tie
  // with another object's (scene/coplanar_parallelograms.h).
  void thicken();

  // Decides hits near its edges exactly (below) from these four corners, in (s, t) order (0, 0),
  // (1, 0), (1, 1), (0, 1): the first is the origin, the others lie within the tolerance of
  // origin + u, + u + v and + v (their float sums may round away from them). For a mesh's face
  // pairs, whose neighbours share these corners to the bit.
  void use_exact_edges(const vec3& c00, const vec3& c10, const vec3& c11, const vec3& c01);

  vec3 origin, u, v;
  dvec3 normal;      // cross(u, v) in double: exact products of the float edges
  vec3 du, dv;       // s = (p - origin) . du, t = (p - origin) . dv for p in the plane
  Bounds3 bounds;    // padded by the tolerance and the test's rounding
  // Edges: false, the test's (s, t) may overlap the neighbour's by kEdgeTolerance (separate
  // quads, whose corners meet only to rounding); true, a hit whose (s, t) lies within
  // kEdgeTolerance of an edge is decided by the side of that edge's line the ray passes, the
  // sign of ((P - o) x (Q - o)) . d for the edge's corners P, Q (Pluecker, as Embree's robust
  // triangles): computed from the same floats in the opposite order, a neighbour's is its exact
  // negation, so the pair neither leaves a crack nor overlaps (an overlap stands out of a convex
  // edge as a lip that grazing rays hit).
  bool exact_edges = false;
  vec3 corners[4];
};

// The point o + s u + t v and its error bound: three products and two sums per coordinate,
// rounded once each (pbrt-v4 section 6.8.1).
inline void parallelogram_point(const vec3& o, const vec3& u, const vec3& v, float s, float t,
                                vec3* p, vec3* error) {
  const vec3 su = s * u, tv = t * v;
  *p = o + su + tv;
  *error = gamma_bound(6) * (abs_components(o) + abs_components(su) + abs_components(tv));
}

// A committed user geometry of `count` parallelograms from `first` on (primitive k is
// first[k]; the array must outlive the Embree scene, and their boxes be final).
EmbreeGeometry make_parallelogram_geometry(RTCDevice device, const Parallelogram* first,
                                          size_t count);

// The Embree callbacks of that geometry (user data: the array). A hit reports (s, t) as Embree's
// (u, v); declared for tests, which compare packets with single rays.
void parallelogram_bounds_fn(const RTCBoundsFunctionArguments* args);
void parallelogram_intersect_fn(const RTCIntersectFunctionNArguments* args);
void parallelogram_occluded_fn(const RTCOccludedFunctionNArguments* args);

}  // namespace penumbra
