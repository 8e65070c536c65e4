#include "renderer/scene/exact_t_check.h"

#include <algorithm>
#include <array>
#include <bit>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "renderer/embree/ray_access.h"

namespace penumbra {
namespace {

inline void check_candidate(const RTCFilterFunctionNArguments* args, const ExactTCheck& check,
                            unsigned n, unsigned i) {
  if (args->valid[i] == 0) return;
  const TriangleMesh* mesh =
      check.plain_mesh(RTCHitN_geomID(args->hit, n, i), RTCHitN_instID(args->hit, n, i, 0));
  if (!mesh) return;
  const vec3 o = embree_ray_origin(args->ray, n, i), d = embree_ray_direction(args->ray, n, i);
  // Embree sets the ray's tfar to the candidate's t while the filter runs. Most candidates of an
  // occlusion query are far from the ray's origin and settled without loading the triangle
  // (mesh_100k: the filter 3.5% -> 1.25% of the profile; docs/performance.md, levers, session 31).
  if (mesh->time_steps() == 1 &&
      embree_hit_certainly_ahead(o, d, RTCRayN_tfar(args->ray, n, i),
                                 vec3(RTCHitN_Ng_x(args->hit, n, i), RTCHitN_Ng_y(args->hit, n, i),
                                      RTCHitN_Ng_z(args->hit, n, i)),
                                 mesh->bounds(), mesh->max_edge()))
    return;
  if (!mesh->ahead_of_ray(RTCHitN_primID(args->hit, n, i), o, d, RTCRayN_time(args->ray, n, i)))
    args->valid[i] = 0;
}

// Embree calls a context filter after the geometry's own filter, for every candidate of every
// geometry (Embree 3 manual, rtcInitIntersectContext).
void exact_t_context_filter(const RTCFilterFunctionNArguments* args) {
  const ExactTCheck& check = *reinterpret_cast<const ExactTContext*>(args->context)->check;
  for_each_filter_lane(args, [&](unsigned n, unsigned i) { check_candidate(args, check, n, i); });
}

// ---- coincident triangles ----

// A triangle's corners at one time step as bit patterns, -0 as +0, sorted as points: equal for
// two triangles with the same vertex set, whatever their order or winding.
using Corners = std::array<uint32_t, 9>;

Corners corners(const TriangleMesh& mesh, uint32_t prim, int step) {
  vec3 v[3];
  mesh.step_triangle(prim, step, v);
  std::array<std::array<uint32_t, 3>, 3> p;
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) p[k][c] = std::bit_cast<uint32_t>(v[k][c] + 0.f);  // -0 + 0 = +0
  // Three compare-exchanges sort three points.
  if (p[1] < p[0]) std::swap(p[0], p[1]);
  if (p[2] < p[1]) std::swap(p[1], p[2]);
  if (p[1] < p[0]) std::swap(p[0], p[1]);
  Corners out;
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) out[size_t(3 * k + c)] = p[k][c];
  return out;
}

uint64_t mix(uint64_t x) {  // splitmix64's finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

uint64_t triangle_hash(const TriangleMesh& mesh, uint32_t prim) {
  uint64_t h = uint64_t(mesh.time_steps());
  for (int s = 0; s < mesh.time_steps(); ++s)
    for (uint32_t w : corners(mesh, prim, s)) h = (h ^ w) * 0x9e3779b97f4a7c15ull;
  return mix(h);
}

bool same_triangle(const TriangleMesh& a, uint32_t pa, const TriangleMesh& b, uint32_t pb) {
  if (a.time_steps() != b.time_steps()) return false;
  for (int s = 0; s < a.time_steps(); ++s)
    if (corners(a, pa, s) != corners(b, pb, s)) return false;
  return true;
}

}  // namespace

ExactTContext ExactTCheck::context(RTCIntersectContextFlags flags) const {
  ExactTContext c;
  rtcInitIntersectContext(&c.embree);
  c.embree.flags = flags;
  if (enabled()) c.embree.filter = exact_t_context_filter;
  c.check = this;
  return c;
}

RTCRayHit exact_t_retrace(RTCScene scene, const ExactTCheck& check, const Ray& ray) {
  ExactTContext c = check.context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
  RTCRayHit rh = embree_ray_hit(ray);
  rtcIntersect1(scene, &c.embree, &rh);
  return rh;
}

bool has_coincident_triangles(const std::vector<const TriangleMesh*>& meshes) {
  // Triangles numbered across meshes; first[m] is mesh m's first number.
  std::vector<uint64_t> first(meshes.size() + 1, 0);
  for (size_t m = 0; m < meshes.size(); ++m) first[m + 1] = first[m] + meshes[m]->triangle_count();
  const uint64_t total = first.back();
  if (total < 2) return false;
  if (total >= 0xFFFFFFFFull) return true;  // cannot number them in the table: assume the worst
  // Open addressing, load at most one half; a slot holds a triangle's number + 1 (0 = empty)
  // and the high half of its hash, so only equal hashes compare vertices.
  size_t capacity = 1;
  while (capacity < 2 * total) capacity <<= 1;
  std::vector<uint32_t> table(capacity, 0), tags(capacity);
  auto mesh_of = [&](uint64_t number) {
    return size_t(std::upper_bound(first.begin(), first.end(), number) - first.begin()) - 1;
  };
  // Every triangle's hash first, on all cores (sorting its corners is most of the work), then
  // the table in triangle order with each slot fetched a few triangles ahead (the table is
  // larger than the caches): Scene::build of a million-triangle mesh took 349 ms with one loop
  // doing both, 224 ms so (docs/mesh-files.md).
  std::vector<uint64_t> hashes(total);
  for (size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = *meshes[m];
    uint64_t* out = hashes.data() + first[m];
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, mesh.triangle_count(), 4096),
                      [&](const tbb::blocked_range<uint32_t>& r) {
                        for (uint32_t prim = r.begin(); prim != r.end(); ++prim)
                          out[prim] = triangle_hash(mesh, prim);
                      });
  }
  constexpr uint64_t kAhead = 8;
  for (uint64_t number = 0; number < total; ++number) {
    if (number + kAhead < total) {
      const size_t ahead = size_t(hashes[number + kAhead]) & (capacity - 1);
      __builtin_prefetch(&table[ahead], 1);
      __builtin_prefetch(&tags[ahead], 1);
    }
    const uint64_t hash = hashes[number];
    const uint32_t tag = uint32_t(hash >> 32);
    size_t slot = size_t(hash) & (capacity - 1);
    for (; table[slot] != 0; slot = (slot + 1) & (capacity - 1)) {
      if (tags[slot] != tag) continue;
      const uint64_t other = table[slot] - 1;
      const size_t m = mesh_of(number), om = mesh_of(other);
      if (same_triangle(*meshes[m], uint32_t(number - first[m]), *meshes[om],
                        uint32_t(other - first[om])))
        return true;
    }
    table[slot] = uint32_t(number + 1);
    tags[slot] = tag;
  }
  return false;
}

}  // namespace penumbra
