#include "renderer/render/adaptive_sampling.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

std::vector<uint32_t> adaptive_sample_limits(const std::vector<double>& deviation, int width,
                                             int height, const AdaptiveLimits& limits) {
  // A pixel's deviation estimated from a few dozen samples is itself noisy, and a pixel that has
  // not yet met a rare bright path (a caustic, a small light seen through glass) reports too low
  // a value and would stop early with a large error. Judging it by at least the mean of its 3x3
  // neighbourhood catches most of those (Cycles judges windows of pixels for the same reason);
  // the maximum of the window instead would also spend samples on the quiet neighbours of every
  // noisy pixel (docs/design-notes.md).
  std::vector<double> judged(deviation.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0.0;
      int count = 0;
      for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx) {
          sum += deviation[size_t(yy) * width + xx];
          ++count;
        }
      judged[size_t(y) * width + x] = std::max(deviation[size_t(y) * width + x], sum / count);
    }

  double mean = 0.0;
  size_t finite = 0;
  for (double d : judged)
    if (std::isfinite(d)) {
      mean += d;
      ++finite;
    }
  mean = finite ? mean / double(finite) : 0.0;

  // n_i = s_i * mean(s) / t^2 (Neyman allocation scaled so the image's relMSE is t^2).
  const double scale = mean / (double(limits.threshold) * limits.threshold);
  const double lo = std::max(1, limits.min_samples), hi = std::max(limits.min_samples, limits.max_samples);
  std::vector<uint32_t> out(judged.size());
  for (size_t i = 0; i < judged.size(); ++i) {
    const double n = std::isfinite(judged[i]) ? std::ceil(judged[i] * scale) : hi;
    out[i] = uint32_t(std::clamp(n, lo, hi));
  }
  return out;
}

}  // namespace penumbra
