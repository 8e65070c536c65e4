#include "renderer/render/adaptive_sampling.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

std::vector<uint32_t> adaptive_sample_limits(const std::vector<double>& deviation, int width,
                                             int height, const AdaptiveLimits& limits) {
  // A pixel is judged by the mean deviation of its neighbours (the 3x3 window without itself),
  // never by its own samples. Its own estimate would make the number of samples it gets depend on
  // the values they took, and a sample mean taken to a value-dependent stopping point is biased:
  // a pixel that has not yet met a rare bright path (a caustic, a small light seen through glass)
  // reports a low deviation and would stop early, dark. With the count decided by the
  // neighbours' samples, which are independent of the pixel's own, the pixel's mean stays
  // unbiased (the accuracy suite's split adaptive renders check it against Mitsuba). The
  // neighbourhood also smooths a deviation estimated from a few dozen samples, itself noisy
  // (Cycles judges windows of pixels for that reason; docs/design-notes.md).
  std::vector<double> judged(deviation.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0.0;
      int count = 0;
      for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx) {
          if (xx == x && yy == y) continue;
          sum += deviation[size_t(yy) * width + xx];
          ++count;
        }
      // A one-pixel image has no neighbours: its own estimate is all there is.
      judged[size_t(y) * width + x] = count ? sum / count : deviation[size_t(y) * width + x];
    }

  // n_i = c * j_i (Neyman allocation on the judged deviations), with c the smallest scale at
  // which the image's predicted relMSE, mean of s_i^2 / n_i over the pixels' own deviations,
  // is t^2 (n_i rounded up and clamped to the limits, as the render takes them). With j = s
  // that is c = mean(s) / t^2; with neighbour-judged counts a pixel noisier than its
  // neighbours gets fewer samples than its own s asks for, and c makes up for it across the
  // image, so the threshold stays the image's relative RMS error. c depends on every pixel's
  // samples, each pixel's own through one term of a mean over all of them.
  const double lo = std::max(1, limits.min_samples), hi = std::max(limits.min_samples, limits.max_samples);
  const double target = double(limits.threshold) * limits.threshold;
  const auto count_at = [&](double c, size_t i) {
    return std::isfinite(judged[i]) ? std::clamp(std::ceil(judged[i] * c), lo, hi) : hi;
  };
  // The pixels that enter the image's error: both deviations known.
  const auto counted = [&](size_t i) { return std::isfinite(deviation[i]) && std::isfinite(judged[i]); };
  // Pixel i's term s_i^2 / n_i of the image's error at scale c.
  const auto term = [&](double c, size_t i) { return deviation[i] * deviation[i] / count_at(c, i); };
  const auto sum_terms = [&](double c) {
    double sum = 0.0;
    for (size_t i = 0; i < judged.size(); ++i)
      if (counted(i)) sum += term(c, i);
    return sum;
  };
  double own_over_judged = 0.0;
  size_t finite = 0;
  for (size_t i = 0; i < judged.size(); ++i)
    if (counted(i)) {
      if (judged[i] > 0.0) own_over_judged += deviation[i] * deviation[i] / judged[i];
      ++finite;
    }
  const auto predicted = [&](double c) { return sum_terms(c) / double(std::max<size_t>(finite, 1)); };
  // The unclamped solution, sum(s^2 / j) / (N t^2), brackets the answer within the clamping's
  // reach: bisect on log c between it / (hi / lo) and it * (hi / lo) (clamping at lo only lowers
  // the error, at hi only raises it).
  const double c0 = finite ? own_over_judged / (double(finite) * target) : 0.0;
  double c = c0;
  if (c0 > 0.0 && std::isfinite(c0)) {
    double below = c0 * lo / hi, above = c0 * hi / lo;
    if (predicted(above) > target) {
      c = above;  // even the cap everywhere does not reach t
    } else {
      for (int k = 0; k < 40 && above > below * (1.0 + 1e-5); ++k) {  // ~20 halvings
        const double mid = std::sqrt(below * above);
        (predicted(mid) <= target ? above : below) = mid;
      }
      c = above;
    }
  }
  // Each pixel's own term taken back out of the scale (leave-one-out): c was solved with pixel
  // i's s_i^2 / n_i among the others, which would let a pixel that met a bright outlier raise its
  // own count. Where the error falls as 1/c (no clamping) c is proportional to the sum of the
  // terms, so without pixel i it is c (T - t_i) / T * N / (N - 1), exactly.
  const double total = sum_terms(c);
  std::vector<uint32_t> out(judged.size());
  for (size_t i = 0; i < judged.size(); ++i) {
    double ci = c;
    if (finite > 1 && total > 0.0 && counted(i))
      ci = c * std::max(0.0, total - term(c, i)) / total * double(finite) / double(finite - 1);
    out[i] = uint32_t(count_at(ci, i));
  }
  return out;
}

}  // namespace penumbra
