#include "renderer/materials/coating_tables.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <list>
#include <mutex>
#include <tuple>
#include <vector>

#include "renderer/materials/coating_tables_integrals.h"
#include "renderer/materials/fresnel.h"

namespace penumbra {
namespace {

std::atomic<int64_t> g_alive{0};

// 1 / (eta^2 (1 - fdr_int)) in double: near 1 (large ior) fdr_int in float would lose the
// difference, and eta^2 overflows a float for the largest valid ior. 0 if nothing gets out.
float diffuse_scale(double eta, double internal_transmittance) {
  const double d = eta * eta * internal_transmittance;
  return d > 0.0 ? float(1.0 / d) : 0.f;
}

CoatingTables smooth_coating_tables(float eta) {
  // Light inside the coating sees the relative ior 1/eta. The exact average makes
  // eta^2 (1 - fdr_int) equal the external diffuse transmittance 1 - fdr_ext (see
  // fresnel_diffuse), so the smooth plastic with a white base reflects exactly 1 at every angle;
  // Mitsuba's polynomial fit gains energy at high ior (docs/design-notes.md).
  const DiffuseFresnel internal = fresnel_diffuse(1.0 / double(eta));
  CoatingTables tables;
  tables.internal_reflectance = float(internal.reflectance);
  tables.diffuse_scale = diffuse_scale(eta, internal.transmittance);
  return tables;
}

// Cosines at which the rough coating's external transmittance t(mu) is tabulated for eta >= 1.
// Where t varies fastest, linear interpolation between uniform nodes over-estimates it, and the
// interpolated t added to the exactly evaluated glossy reflection then exceeds 1. So the nodes
// cluster at grazing incidence, where t has its steep foot: mu = x^2 for x uniform in [0, 1]
// (docs/design-notes.md has the range over which this keeps the sum <= 1).
std::array<float, kCoatingTableRes> grazing_nodes() {
  constexpr int n = kCoatingTableRes;
  std::array<float, n> nodes{};
  for (int i = 0; i < n; ++i) {
    const double x = double(i) / (n - 1);
    nodes[i] = float(x * x);
  }
  nodes[n - 1] = 1.f;
  return nodes;
}

// eta < 1 (the coating is the thinner medium): t rises from 0 (total reflection below the
// critical cosine mu_c = sqrt(1 - eta^2) for a smooth coating) within a foot whose width scales
// with alpha. A fixed clustering onto mu_c leaves too few nodes in a narrow foot and the
// interpolated t then exceeds the bound 1 - E_spec(mu) (docs/design-notes.md). So the nodes are
// placed adaptively: a coarse clustering (cubic below mu_c, quadratic above), then repeated
// bisection of the cell whose midpoint value departs most from the chord (the
// interpolation error of a piecewise-linear table, de Boor 1978 ch. III), which puts the nodes
// where the foot's curvature is, whatever alpha and eta are.
void adaptive_transmittance_table(const GgxDistribution& distr, float eta,
                                  std::array<float, kCoatingTableCapacity>& cosines,
                                  std::array<float, kCoatingTableCapacity>& values) {
  constexpr int n = kCoatingTableCapacity;
  constexpr int seed = 16;  // nodes of the coarse clustering
  const auto t_at = [&](double mu) {
    return coating_transmittance(distr, std::max(1e-6f, float(mu)), eta);
  };
  const double mu_c = std::sqrt(1.0 - double(eta) * eta);
  std::vector<double> mu(seed);
  constexpr int below = seed / 2;
  for (int i = 0; i <= below; ++i) {
    const double w = 1.0 - double(i) / below;
    mu[i] = mu_c * (1.0 - w * w * w);
  }
  for (int i = below + 1; i < seed; ++i) {
    const double v = double(i - below) / (seed - 1 - below);
    mu[i] = mu_c + (1.0 - mu_c) * v * v;
  }
  mu[seed - 1] = 1.0;
  std::vector<double> t(seed), mid(seed - 1);
  tbb::parallel_for(0, seed, [&](int i) { t[i] = t_at(mu[i]); });
  tbb::parallel_for(0, seed - 1, [&](int i) { mid[i] = t_at(0.5 * (mu[i] + mu[i + 1])); });
  const auto error = [&](size_t i) {
    // Cells below float resolution cannot be split further.
    if (float(0.5 * (mu[i] + mu[i + 1])) <= float(mu[i]) ||
        float(0.5 * (mu[i] + mu[i + 1])) >= float(mu[i + 1]))
      return -1.0;
    return std::abs(mid[i] - 0.5 * (t[i] + t[i + 1]));
  };
  while (int(mu.size()) < n) {
    size_t worst = 0;
    double worst_error = -1.0;
    for (size_t i = 0; i + 1 < mu.size(); ++i) {
      const double e = error(i);
      if (e > worst_error) worst_error = e, worst = i;
    }
    const double m = 0.5 * (mu[worst] + mu[worst + 1]);
    if (worst_error < 0.0) {  // nothing left to split: pad with duplicates of the last node
      mu.push_back(1.0), t.push_back(t.back()), mid.push_back(t.back());
      continue;
    }
    const double tm = mid[worst];
    const double left = t_at(0.5 * (mu[worst] + m));
    const double right = t_at(0.5 * (m + mu[worst + 1]));
    mu.insert(mu.begin() + worst + 1, m);
    t.insert(t.begin() + worst + 1, tm);
    mid[worst] = left;
    mid.insert(mid.begin() + worst + 1, right);
  }
  for (int i = 0; i < n; ++i) {
    cosines[i] = float(mu[i]);
    values[i] = float(t[i]);
  }
  cosines[0] = 0.f;
  cosines[n - 1] = 1.f;
}

// 2 \int_0^1 t(mu) mu dmu for the piecewise-linear interpolant of the table, exactly.
double table_diffuse_average(const CoatingTables& tables) {
  const auto& cosines = tables.cosines;
  const auto& values = tables.transmittance;
  double sum = 0.0;
  for (int i = 0; i + 1 < tables.nodes; ++i) {
    const double a = cosines[i], b = cosines[i + 1];
    sum += (b - a) / 6.0 * (values[i] * (2.0 * a + b) + values[i + 1] * (a + 2.0 * b));
  }
  return 2.0 * sum;
}

CoatingTables rough_coating_tables(const GgxDistribution& distr, float eta) {
  constexpr int n = kCoatingTableRes;
  CoatingTables tables;
  if (eta < 1.f) {
    // The diffuse factor from reciprocity: for the same (separable-Smith, hence reciprocal)
    // microfacet BTDF, eta^2 (1 - fdr_int) equals the external diffuse transmittance
    // 2 \int t(mu) mu dmu (radiance / n^2 is invariant, Veach 1997 sec. 5.2), as for the smooth
    // coating. Taking the latter from the interpolated table itself makes the diffuse factor D =
    // diffuse_scale 2 \int t mu dmu exactly 1, so a white plastic reflects E_spec(mu_i) + t(mu_i)
    // <= 1. Mitsuba's mean over uniform nodes misses the total-internal-reflection jump of
    // R_int at mu_c and gains energy; there is no Mitsuba result to match below ior 1.
    tables.nodes = kCoatingTableCapacity;
    adaptive_transmittance_table(distr, eta, tables.cosines, tables.transmittance);
    const double external = table_diffuse_average(tables);
    tables.internal_reflectance = float(1.0 - external / (double(eta) * eta));
    tables.diffuse_scale = external > 0.0 ? float(1.0 / external) : 0.f;
    return tables;
  }
  // eta >= 1: tabulate t(mu) at the grazing-clustered nodes (clamped away from 0) and average the
  // internal reflectance 2 \int R_int(mu) mu dmu as the mean over mu = linspace(0, 1) -- Mitsuba
  // 3's roughplastic takes the same mean (and tabulates t on uniform nodes), so the diffuse part
  // matches it. That mean underestimates the average by about (fdr_int - R_int(1)) / 64, so the
  // rough plastic returns less light than the smooth one, not more (docs/design-notes.md).
  tables.nodes = n;
  tables.square_nodes = true;
  const std::array<float, n> nodes = grazing_nodes();
  std::copy(nodes.begin(), nodes.end(), tables.cosines.begin());
  std::array<double, n> internal{};
  tbb::parallel_for(0, n, [&](int i) {
    tables.transmittance[i] = coating_transmittance(distr, std::max(1e-6f, tables.cosines[i]), eta);
    const float mu = std::max(1e-6f, float(i) / float(n - 1));
    internal[i] = coating_reflectance(distr, mu, 1.f / eta) * mu;
  });
  double sum = 0.0;
  for (double v : internal) sum += v;  // fixed order: the result does not depend on threads
  const double reflectance = 2.0 * sum / n;
  tables.internal_reflectance = float(reflectance);
  tables.diffuse_scale = diffuse_scale(eta, 1.0 - reflectance);
  return tables;
}

}  // namespace

CoatingTables::CoatingTables() { ++g_alive; }
CoatingTables::~CoatingTables() { --g_alive; }
CoatingTables::CoatingTables(const CoatingTables& o)
    : nodes(o.nodes),
      square_nodes(o.square_nodes),
      cosines(o.cosines),
      transmittance(o.transmittance),
      internal_reflectance(o.internal_reflectance),
      diffuse_scale(o.diffuse_scale) {
  ++g_alive;
}

int64_t coating_tables_alive() { return g_alive.load(); }

CoatingTables make_coating_tables(bool smooth, const GgxDistribution& distr, float eta) {
  return smooth ? smooth_coating_tables(eta) : rough_coating_tables(distr, eta);
}

namespace {

// The process-wide LRU: a list in order of use (front: most recent) and an index into it.
class CoatingTableLru {
 public:
  using Key = std::tuple<bool, float, float>;

  std::shared_ptr<const CoatingTables> get(bool smooth, const GgxDistribution& distr, float eta) {
    const Key key(smooth, smooth ? 0.f : distr.alpha(), eta);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (auto found = index_.find(key); found != index_.end()) {
        entries_.splice(entries_.begin(), entries_, found->second);
        return found->second->second;
      }
    }
    // Computed without the lock: the tables run a parallel_for, and a TBB thread waiting in it
    // may take another task that asks this cache (a lock held here would then deadlock), and a
    // miss must not stall every other material's lookup.
    auto tables = std::make_shared<const CoatingTables>(make_coating_tables(smooth, distr, eta));
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto found = index_.find(key); found != index_.end()) {  // another thread was faster
      entries_.splice(entries_.begin(), entries_, found->second);
      return found->second->second;
    }
    if (capacity_ == 0) return tables;
    entries_.emplace_front(key, tables);
    index_.emplace(key, entries_.begin());
    evict_to(capacity_);
    return tables;
  }

  size_t size() {
    std::lock_guard<std::mutex> lock(mutex_);
    return entries_.size();
  }
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    evict_to(0);
  }
  size_t set_capacity(size_t capacity) {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t old = capacity_;
    capacity_ = capacity;
    evict_to(capacity_);
    return old;
  }

 private:
  void evict_to(size_t n) {
    while (entries_.size() > n) {
      index_.erase(entries_.back().first);
      entries_.pop_back();
    }
  }

  std::mutex mutex_;
  size_t capacity_ = kCoatingTableLruCapacity;
  std::list<std::pair<Key, std::shared_ptr<const CoatingTables>>> entries_;
  std::map<Key, decltype(entries_)::iterator> index_;
};

CoatingTableLru& lru() {
  // Never destroyed: a scene destroyed during static destruction may still release tables.
  static CoatingTableLru* const instance = new CoatingTableLru();
  return *instance;
}

}  // namespace

std::shared_ptr<const CoatingTables> shared_coating_tables(bool smooth,
                                                           const GgxDistribution& distr,
                                                           float eta) {
  return lru().get(smooth, distr, eta);
}
size_t coating_table_lru_size() { return lru().size(); }
void clear_coating_table_lru() { lru().clear(); }
size_t set_coating_table_lru_capacity(size_t capacity) { return lru().set_capacity(capacity); }

const CoatingTables& CoatingTableCache::get(bool smooth, const GgxDistribution& distr, float eta) {
  const std::pair<float, float> key(smooth ? 0.f : distr.alpha(), eta);
  auto& slot = tables_[key];
  if (!slot) slot = shared_coating_tables(smooth, distr, eta);
  return *slot;
}

}  // namespace penumbra
