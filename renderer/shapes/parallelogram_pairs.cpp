#include "renderer/shapes/parallelogram_pairs.h"

#include <algorithm>
#include <optional>

namespace penumbra {
namespace {

struct Pairing {
  FacePairSlots slots;
  vec3 a, b, c, d;
};

// Triangle `first` as (A, B, C) around an edge A-C that `second` walks from A to C, the other
// way round (same winding), as (A, C, D).
std::optional<Pairing> shared_edge(const vec3 first[3], const vec3 second[3]) {
  for (int r = 0; r < 3; ++r) {
    const int ia = r, ib = (r + 1) % 3, ic = (r + 2) % 3;
    for (int q = 0; q < 3; ++q) {
      const int ja = q, jc = (q + 1) % 3, jd = (q + 2) % 3;
      if (second[ja] == first[ia] && second[jc] == first[ic] && second[jd] != first[ib]) {
        Pairing p;
        p.slots.first = {uint8_t(ia), uint8_t(ib), uint8_t(ic)};
        p.slots.second = {uint8_t(ja), uint8_t(jc), uint8_t(jd)};
        p.a = first[ia];
        p.b = first[ib];
        p.c = first[ic];
        p.d = second[jd];
        return p;
      }
    }
  }
  return std::nullopt;
}

// Whether B + (C - B) + (A - B) lies within the allowed distance of D, and the corner angle is
// not a sliver's. In double: the floats' sums and products there are exact or nearly so.
bool is_parallelogram(const Pairing& p) {
  const dvec3 a(p.a), b(p.b), c(p.c), d(p.d);
  const dvec3 u = c - b, v = a - b;
  const double lu = glm::length(u), lv = glm::length(v);
  if (!(lu > 0.0 && lv > 0.0)) return false;
  if (!(glm::length(glm::cross(u, v)) >= 1e-3 * lu * lv)) return false;
  const dvec3 off = glm::abs(a + c - b - d);
  const double allowed = 0.25 * double(Parallelogram::kEdgeTolerance) * std::min(lu, lv);
  return off.x <= allowed && off.y <= allowed && off.z <= allowed;
}

}  // namespace

FacePairs pair_into_parallelograms(const std::vector<vec3>& positions,
                                   const std::vector<uint32_t>& indices) {
  const size_t triangles = indices.size() / 3;
  if (triangles == 0 || triangles % 2 != 0) return {};
  FacePairs out;
  out.shapes.reserve(triangles / 2);
  out.slots.reserve(triangles / 2);
  for (size_t k = 0; k < triangles; k += 2) {
    vec3 first[3], second[3];
    for (int j = 0; j < 3; ++j) {
      first[j] = positions[indices[3 * k + j]];
      second[j] = positions[indices[3 * k + 3 + j]];
    }
    const std::optional<Pairing> p = shared_edge(first, second);
    if (!p || !is_parallelogram(*p)) return {};
    Parallelogram& q = out.shapes.emplace_back(QuadDesc{p->b, p->c - p->b, p->a - p->b});
    q.use_exact_edges(p->b, p->c, p->d, p->a);
    out.slots.push_back(p->slots);
  }
  return out;
}

}  // namespace penumbra
