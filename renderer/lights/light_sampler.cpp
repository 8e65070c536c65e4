#include "renderer/lights/light_sampler.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

LightSampler::LightSampler(const std::vector<float>& powers) {
  const size_t n = powers.size();
  pmf_.assign(n, 0.f);
  cdf_.assign(n, 0.f);
  if (n == 0) return;
  std::vector<double> power(n);
  double total = 0.0;
  for (size_t i = 0; i < n; ++i) {
    power[i] = std::max(0.f, powers[i]);
    if (!std::isfinite(power[i])) power[i] = 0.0;
    total += power[i];
  }
  double acc = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double by_power = total > 0.0 ? power[i] / total : 1.0 / double(n);
    pmf_[i] = float(0.5 * by_power + 0.5 / double(n));
    acc += pmf_[i];
    cdf_[i] = float(acc);
  }
  cdf_.back() = 1.f;
}

int LightSampler::choose(float u) const {
  return int(std::min<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin(),
                              cdf_.size() - 1));
}

}  // namespace penumbra
