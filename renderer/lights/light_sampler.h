#pragma once
// The choice of one light for next-event estimation; it knows lights only by their power.
#include <cstddef>
#include <vector>

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

  bool empty() const { return cdf_.empty(); }
  // The light that u in [0, 1) selects.
  int choose(float u) const;
  // Probability that choose() returns `light` (0 for a light left out).
  float pmf(int light) const { return pmf_[light]; }
  // The cumulative probabilities choose() searches (the last is 1), for choosing in SIMD.
  const std::vector<float>& cdf() const { return cdf_; }

 private:
  std::vector<float> pmf_, cdf_;
};

}  // namespace penumbra
