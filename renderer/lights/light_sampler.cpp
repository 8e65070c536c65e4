#include "renderer/lights/light_sampler.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

LightSampler::LightSampler(const std::vector<float>& powers)
    : LightSampler(powers, std::vector<bool>(powers.size(), true)) {}

LightSampler::LightSampler(const std::vector<float>& powers, const std::vector<bool>& sampled)
    : LightSampler(powers, sampled, {}) {}

LightSampler::LightSampler(const std::vector<float>& powers, const std::vector<bool>& sampled,
                           const std::vector<std::optional<LightBounds>>& places) {
  const size_t n = powers.size();
  // A light past the end of `sampled` counts as left out (in every loop below).
  const auto in = [&](size_t i) { return i < sampled.size() && sampled[i]; };
  const auto placed = [&](size_t i) { return in(i) && i < places.size() && places[i].has_value(); };
  size_t count = 0, placed_count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (in(i)) ++count;
    if (placed(i)) ++placed_count;
  }
  pmf_.assign(n, 0.f);
  if (count == 0) return;
  std::vector<double> power(n, 0.0);
  double total = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!in(i)) continue;
    power[i] = std::max(0.f, powers[i]);
    if (!std::isfinite(power[i])) power[i] = 0.0;
    total += power[i];
  }
  for (size_t i = 0; i < n; ++i)
    if (in(i)) {
      const double by_power = total > 0.0 ? power[i] / total : 1.0 / double(count);
      pmf_[i] = float(0.5 * by_power + 0.5 / double(count));
    }

  const bool use_tree = placed_count >= kTreeFrom;
  std::vector<LightBounds> bounds;
  std::vector<int> ids;
  double group = 0.0;
  if (use_tree) {
    in_tree_.assign(n, false);
    for (size_t i = 0; i < n; ++i) {
      if (!placed(i)) continue;
      in_tree_[i] = true;
      group += pmf_[i];
      LightBounds b = *places[i];
      // The importance's numerator is the light's largest radiant intensity, which its power
      // bounds as P / (4 pi) for light leaving every way (a point, a sphere) and P / pi for a
      // flat Lambertian emitter (L A of P = pi L A). Power itself would favour points and
      // spheres four times over panels of the same intensity.
      b.phi = float(power[i] / (b.normals.cos_theta <= -1.f ? 4.0 * M_PI : M_PI));
      bounds.push_back(b);
      ids.push_back(int(i));
    }
    tree_ = LightTree(bounds, ids);
    tree_pmf_ = float(group);
    spatial_ = true;
  }
  // The entries: each sampled light (in index order) and, with a tree, its group after them.
  double acc = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!in(i) || (use_tree && in_tree_[i])) continue;
    acc += pmf_[i];
    cdf_.push_back(float(acc));
    entry_light_.push_back(int(i));
  }
  if (use_tree) {
    acc += group;
    cdf_.push_back(float(acc));
    entry_light_.push_back(-1);
  }
  // The last entry takes whatever rounding left below 1.
  cdf_.back() = 1.f;
  if (!use_tree && cdf_.size() != n) {
    // Without a tree, entries are lights: keep an entry per light (left-out lights with empty
    // intervals), so the SIMD choice, which counts entries, returns light indices.
    std::vector<float> full(n, 0.f);
    std::vector<int> lights(n);
    size_t e = 0;
    float last = 0.f;
    for (size_t i = 0; i < n; ++i) {
      lights[i] = int(i);
      if (e < entry_light_.size() && entry_light_[e] == int(i)) last = cdf_[e++];
      full[i] = last;
    }
    // A left-out light after the last sampled one keeps an empty interval at 1.
    for (size_t i = size_t(entry_light_.back()); i < n; ++i) full[i] = 1.f;
    cdf_ = std::move(full);
    entry_light_ = std::move(lights);
  }
}

int LightSampler::choose_entry(float u) const {
  return int(std::min<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin(),
                              cdf_.size() - 1));
}

float LightSampler::group_u(int e, float u) const {
  const float lo = e > 0 ? cdf_[size_t(e) - 1] : 0.f, hi = cdf_[size_t(e)];
  return hi > lo ? std::clamp((u - lo) / (hi - lo), 0.f, kOneMinusEpsilon) : 0.f;
}

int LightSampler::choose(float u, const vec3& p, const vec3& n, float* pmf) const {
  const int e = choose_entry(u);
  const int light = entry_light_[size_t(e)];
  if (light >= 0) {
    *pmf = pmf_[size_t(light)];
    return light;
  }
  float tree_pmf;
  const int chosen = tree_.choose(p, n, group_u(e, u), &tree_pmf);
  *pmf = tree_pmf_ * tree_pmf;
  return chosen;
}

void LightSampler::choose_many(size_t n, const vec3* p, const vec3* normal, const float* u, int* light,
                               float* pmf) const {
  // Lights outside the tree at once; the tree's group gathered and walked together. (The
  // gather buffers are the thread's, kept between calls: a stage calls this every bounce.)
  struct Buffers {
    std::vector<vec3> group_p, group_n;
    std::vector<float> group_v, walk_pmf;
    std::vector<int> group_light;
    std::vector<size_t> group_of;
  };
  thread_local Buffers buffers;
  auto& [group_p, group_n, group_v, walk_pmf, group_light, group_of] = buffers;
  if (entry_light_.size() == 1 && entry_light_[0] < 0) {
    // Every light in the tree: the points walk it as they are.
    group_v.resize(n);
    for (size_t k = 0; k < n; ++k) group_v[k] = group_u(0, u[k]);
    tree_.choose_many(n, p, normal, group_v.data(), light, pmf);
    for (size_t k = 0; k < n; ++k) pmf[k] = tree_pmf_ * pmf[k];
    return;
  }
  group_p.clear();
  group_n.clear();
  group_v.clear();
  group_of.clear();
  for (size_t k = 0; k < n; ++k) {
    const int e = choose_entry(u[k]);
    light[k] = entry_light_[size_t(e)];
    if (light[k] >= 0) {
      pmf[k] = pmf_[size_t(light[k])];
      continue;
    }
    group_of.push_back(k);
    group_p.push_back(p[k]);
    group_n.push_back(normal[k]);
    group_v.push_back(group_u(e, u[k]));
  }
  if (group_of.empty()) return;
  group_light.resize(group_of.size());
  walk_pmf.resize(group_of.size());
  tree_.choose_many(group_of.size(), group_p.data(), group_n.data(), group_v.data(), group_light.data(),
                    walk_pmf.data());
  for (size_t j = 0; j < group_of.size(); ++j) {
    light[group_of[j]] = group_light[j];
    pmf[group_of[j]] = tree_pmf_ * walk_pmf[j];
  }
}

}  // namespace penumbra
