#pragma once
// What a plastic's coating needs that depends only on (alpha, eta): computed once per distinct
// coating of a scene, owned by the scene's cache, and pointed to (not copied) by each PlasticBsdf.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <utility>

#include "renderer/materials/microfacet.h"

namespace penumbra {

// Capacity of the rough transmittance table over cos(theta) in [0, 1]: 64 nodes (as Mitsuba) for
// ior >= 1; below ior 1 the nodes are placed adaptively and twice as many are used.
inline constexpr int kCoatingTableRes = 64;
inline constexpr int kCoatingTableCapacity = 2 * kCoatingTableRes;

// What a coating needs that depends only on (alpha, eta): the rough coating's transmittance
// table, the internal diffuse reflectance fdr_int and the diffuse factor 1 / (eta^2 (1 - fdr_int)).
struct CoatingTables {
  CoatingTables();
  ~CoatingTables();
  CoatingTables(const CoatingTables&);
  CoatingTables& operator=(const CoatingTables&) = default;

  // Rough coating only: t at the increasing cosines (nodes[0] = 0, nodes[n - 1] = 1).
  int nodes = 0;
  // Whether node i lies at (i / (nodes - 1))^2 (rounded to float): the interval holding a cosine
  // is then found from its square root instead of by bisection (interval()).
  bool square_nodes = false;
  std::array<float, kCoatingTableCapacity> cosines{};
  std::array<float, kCoatingTableCapacity> transmittance{};
  float internal_reflectance = 0.f;
  float diffuse_scale = 0.f;

  // The i in [0, nodes - 2] whose interval [cosines[i], cosines[i + 1]) holds mu in [0, 1]: the
  // last node at or below mu, not counting the last node (the bisection std::upper_bound over
  // cosines[1, nodes - 1) does). Square nodes: a guess from sqrt(mu), then corrected against the
  // stored nodes, so the answer is the bisection's exactly whatever the rounding (a rough
  // plastic looks this up several times per sample; bisection was 8% of its render).
  int interval(float mu) const {
    if (!square_nodes) {
      const float* upper = std::upper_bound(cosines.data() + 1, cosines.data() + nodes - 1, mu);
      return int(upper - cosines.data()) - 1;
    }
    const float root = mu > 0.f ? std::sqrt(std::min(mu, 1.f)) : 0.f;  // NaN: 0
    int i = std::min(int(root * float(nodes - 1)), nodes - 2);
    while (i < nodes - 2 && cosines[i + 1] <= mu) ++i;
    while (i > 0 && cosines[i] > mu) --i;
    return i;
  }
};

// The tables of a smooth (alpha ignored) or rough GGX coating of relative ior eta.
CoatingTables make_coating_tables(bool smooth, const GgxDistribution& distr, float eta);

// Tables shared by the materials of one scene. The rough tables cost ~3 * 10^5 microfacet
// evaluations (the smooth ones a few hundred Fresnel evaluations) and depend only on
// (alpha, eta), so every plastic with the same coating computes them once. The scene owns the
// cache and its plastics point into it (entries never move: they are held by shared_ptr). The
// tables come from the process-wide cache below, so a service that renders the same materials
// again and again computes them once; a scene's cache holds its tables alive for as long as the
// scene lives, whatever the process-wide cache evicts meanwhile.
class CoatingTableCache {
 public:
  const CoatingTables& get(bool smooth, const GgxDistribution& distr, float eta);
  size_t size() const { return tables_.size(); }

 private:
  std::map<std::pair<float, float>, std::shared_ptr<const CoatingTables>> tables_;
};

// The process-wide cache of coating tables: least recently used first out, bounded in entries
// (a table is about 1 KB), thread-safe. Key (smooth, alpha, eta); a smooth coating's alpha is
// ignored. Two threads missing the same key at once may both compute it (identical tables); the
// cache keeps one. Nothing beyond the bound and what live scenes hold stays alive.
inline constexpr size_t kCoatingTableLruCapacity = 128;
std::shared_ptr<const CoatingTables> shared_coating_tables(bool smooth,
                                                           const GgxDistribution& distr, float eta);
// Entries held by the process-wide cache.
size_t coating_table_lru_size();
// For tests: drop every entry / change the bound (evicting down to it); returns the old bound.
void clear_coating_table_lru();
size_t set_coating_table_lru_capacity(size_t capacity);

// How many CoatingTables exist in the process (a test checks that nothing accumulates).
int64_t coating_tables_alive();

}  // namespace penumbra
