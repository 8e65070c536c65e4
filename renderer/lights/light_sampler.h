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

  bool empty() const { return pmf_.empty(); }
  // The light that u in [0, 1) selects.
  int choose(float u) const;
  // Probability that choose() returns `light`.
  float pmf(int light) const { return pmf_[light]; }
  // The cumulative probabilities choose() searches (the last is 1), for choosing in SIMD.
  const std::vector<float>& cdf() const { return cdf_; }

 private:
  std::vector<float> pmf_, cdf_;
};

}  // namespace penumbra
