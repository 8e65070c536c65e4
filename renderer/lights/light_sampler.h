#pragma once
// The choice of one light for next-event estimation. Lights without a place in space (an
// environment, a distant sun) are chosen by their power; lights with one, when there are
// kTreeFrom or more, together as a group whose members are chosen by where the shading point is
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
  // their phi is ignored, the powers are used). When kTreeFrom or more sampled lights have a place,
  // the group of them is chosen with the probability its lights have by the rule above, and
  // one of them by the light tree at the shading point.
  LightSampler(const std::vector<float>& powers, const std::vector<bool>& sampled,
               const std::vector<std::optional<LightBounds>>& places);

  // Lights with a place from which the tree chooses among them. With few lights the choice by
  // power does as well or better: all_lights (four lights with a place) had 0.94 of its direct
  // light's error with the tree but 1.3-1.5 of its whole error, from rare bright samples of its
  // point light on its glossy sphere: the tree's importance does not see the BSDF (with the
  // sphere made diffuse the tree has 0.75 of the variance; docs/performance.md, levers,
  // sessions 42 and 43).
  static constexpr size_t kTreeFrom = 8;

  bool empty() const { return cdf_.empty(); }
  // Whether the choice depends on the shading point (a light tree is in use); if not, choose(u)
  // and pmf(light) answer for every point, and cdf() lists the lights themselves.
  // (Also when the tree turned out empty, every light in it having no power: its group then
  // gives no light, in every driver alike.)
  bool spatial() const { return spatial_; }

  // The light that u in [0, 1) selects at point p on a surface of geometric normal n (0 for
  // none), its probability in *pmf; -1 (and *pmf 0) if the tree's lights were chosen and none
  // of them can reach p.
  int choose(float u, const vec3& p, const vec3& n, float* pmf) const;
  // choose() for count points at once (p[k], n[k], u[k] -> light[k], pmf[k]): the same choices
  // and bits, the tree's walks overlapped (LightTree::choose_many).
  void choose_many(size_t count, const vec3* p, const vec3* n, const float* u, int* light, float* pmf) const;
  // Probability that choose(u, p, n) returns `light` (0 for a light left out or out of reach).
  float pmf(int light, const vec3& p, const vec3& n) const {
    return in_tree_.empty() || !in_tree_[size_t(light)] ? pmf_[size_t(light)]
                                                         : tree_pmf_ * tree_.pmf(p, n, light);
  }

  // Without a tree (!spatial()): the light that u selects; and the probability of a light
  // outside the tree (any light without one).
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
  bool spatial_ = false;
  LightTree tree_;
};

}  // namespace penumbra
