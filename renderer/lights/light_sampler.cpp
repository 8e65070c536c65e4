#include "renderer/lights/light_sampler.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

LightSampler::LightSampler(const std::vector<float>& powers)
    : LightSampler(powers, std::vector<bool>(powers.size(), true)) {}

LightSampler::LightSampler(const std::vector<float>& powers, const std::vector<bool>& sampled) {
  const size_t n = powers.size();
  // A light past the end of `sampled` counts as left out (in every loop below).
  const auto in = [&](size_t i) { return i < sampled.size() && sampled[i]; };
  size_t count = 0, last = 0;
  for (size_t i = 0; i < n; ++i)
    if (in(i)) ++count, last = i;
  pmf_.assign(n, 0.f);
  if (count == 0) return;
  cdf_.assign(n, 0.f);
  std::vector<double> power(n, 0.0);
  double total = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!in(i)) continue;
    power[i] = std::max(0.f, powers[i]);
    if (!std::isfinite(power[i])) power[i] = 0.0;
    total += power[i];
  }
  double acc = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (in(i)) {
      const double by_power = total > 0.0 ? power[i] / total : 1.0 / double(count);
      pmf_[i] = float(0.5 * by_power + 0.5 / double(count));
      acc += pmf_[i];
    }
    cdf_[i] = float(acc);
  }
  // The last sampled light takes whatever rounding left below 1; a left-out light after it keeps
  // an empty interval, so neither choose() nor a count of cdf <= u ever lands on it.
  for (size_t i = last; i < n; ++i) cdf_[i] = 1.f;
}

int LightSampler::choose(float u) const {
  return int(std::min<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin(),
                              cdf_.size() - 1));
}

}  // namespace penumbra
