#pragma once
// The choice of one light for next-event estimation. Lights without a place in space (an
// environment, a distant sun) are chosen by their power; lights with one, when there are two or
// more, together as a group whose members are chosen by where the shading point is
// (lights/light_tree.h): near and bright lights more often than far or dim ones.
#include <cstddef>
#include <optional>
#include <vector>

#include "renderer/lights/light_tree.h"

namespace penumbra {

class LightSampler {
 public:
  LightSampler() = default;
  // Half proportional to each light's power, half uniform, so a dim but important light is
  // never starved. Negative or non-finite powers count as 0.
  explicit LightSampler(const std::vector<float>& powers);
  // The same over the lights with sampled[i] true; the others are never chosen (pmf 0), so a
  // light's index is the same in both. Empty if no light is sampled (pmf() is then 0 for all).
  LightSampler(const std::vector<float>& powers, const std::vector<bool>& sampled);
  // With where the lights are (places[i]: light i's bounds, nullopt for a light without a place;
  // their phi is ignored, the powers are used). When two or more sampled lights have a place,
  // the group of them is chosen with the probability its lights have by the rule above, and
  // one of them by the light tree at the shading point.
  LightSampler(const std::vector<float>& powers, const std::vector<bool>& sampled,
               const std::vector<std::optional<LightBounds>>& places);

  bool empty() const { return cdf_.empty(); }
  // Whether the choice depends on the shading point (a light tree is in use); if not, choose(u)
  // and pmf(light) answer for every point, and cdf() lists the lights themselves.
  bool spatial() const { return !tree_.empty(); }

  // The light that u in [0, 1) selects at point p, its probability in *pmf; -1 (and *pmf 0) if
  // the tree's lights were chosen and none of them can reach p.
  int choose(float u, const vec3& p, float* pmf) const;
  // choose() for n points at once (p[k], u[k] -> light[k], pmf[k]): the same choices and bits,
  // the tree's walks overlapped (LightTree::choose_many).
  void choose_many(size_t n, const vec3* p, const float* u, int* light, float* pmf) const;
  // Probability that choose(u, p) returns `light` (0 for a light left out or out of reach).
  float pmf(int light, const vec3& p) const {
    return in_tree_.empty() || !in_tree_[size_t(light)] ? pmf_[size_t(light)]
                                                         : tree_pmf_ * tree_.pmf(p, light);
  }

  // Without a tree (!spatial()): the light that u selects, and its probability.
  int choose(float u) const { return entry_light_[size_t(choose_entry(u))]; }
  float pmf(int light) const { return pmf_[size_t(light)]; }
  // The cumulative probabilities choose() searches (the last is 1), for choosing in SIMD: over
  // the lights without a tree, over the lights without a place and then the tree's group with one.
  const std::vector<float>& cdf() const { return cdf_; }

 private:
  int choose_entry(float u) const;
  // u stretched over the group's entry e of the cdf, to [0, 1).
  float group_u(int e, float u) const;

  std::vector<float> pmf_;       // per light; for the tree's lights their share of the group's
  std::vector<float> cdf_;       // per entry
  std::vector<int> entry_light_;  // per entry: a light, or -1 for the tree's group
  std::vector<bool> in_tree_;    // per light (empty without a tree)
  float tree_pmf_ = 0.f;         // the group's probability
  LightTree tree_;
};

}  // namespace penumbra
