#pragma once
// Per-pixel accumulation of radiance samples (box filter: a sample counts for its own pixel only,
// so every pixel is written by exactly one tile and no locking is needed).
#include <cstdint>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/math.h"

namespace penumbra {

class Film {
 public:
  Film(int width, int height);

  // Returns false (and records nothing) for a non-finite sample.
  bool add_sample(int x, int y, const Spectrum& value) {
    if (!is_finite(value)) return false;
    Pixel& p = pixels_[size_t(y) * width_ + x];
    for (int c = 0; c < 3; ++c) {
      const double v = value[c];
      p.sum[c] += v;
      p.sum_sq[c] += v * v;
    }
    ++p.n;
    return true;
  }
  // add_sample for a run of n samples of one pixel, value_of(k) for k = 0..n-1: the same sums
  // to the bit, added in that order, but in registers, the pixel loaded and stored once (one
  // add_sample after another waits on the previous one's stores). Returns how many were
  // non-finite (not recorded).
  template <class ValueOf>
  uint32_t add_samples(int x, int y, size_t n, ValueOf&& value_of) {
    Pixel& p = pixels_[size_t(y) * width_ + x];
    double sum[3] = {p.sum[0], p.sum[1], p.sum[2]};
    double sum_sq[3] = {p.sum_sq[0], p.sum_sq[1], p.sum_sq[2]};
    uint32_t taken = 0;
    for (size_t k = 0; k < n; ++k) {
      const Spectrum& value = value_of(k);
      if (!is_finite(value)) continue;
      for (int c = 0; c < 3; ++c) {
        const double v = value[c];
        sum[c] += v;
        sum_sq[c] += v * v;
      }
      ++taken;
    }
    for (int c = 0; c < 3; ++c) {
      p.sum[c] = sum[c];
      p.sum_sq[c] = sum_sq[c];
    }
    p.n += taken;
    return uint32_t(n) - taken;
  }
  uint32_t samples(int x, int y) const { return pixels_[size_t(y) * width_ + x].n; }
  // Relative standard deviation of one sample of the pixel (for adaptive sampling): the root of
  // (1/3) sum_c var_c / (mean_c^2 + kRelativeFloor), so that the pixel's contribution to the
  // image's relMSE after n samples is relative_deviation^2 / n. Infinite below two samples.
  double relative_deviation(int x, int y) const;
  // The floor of relMSE's denominator (mean^2 + 0.01), the usual convention: pixels darker than
  // about 0.1 are judged by absolute rather than relative error.
  static constexpr double kRelativeFloor = 1e-2;

  Image resolve() const;
  Image resolve_variance() const;  // variance of each pixel's mean, per channel

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct Pixel {
    double sum[3] = {0, 0, 0};
    double sum_sq[3] = {0, 0, 0};
    uint32_t n = 0;
  };
  int width_, height_;
  std::vector<Pixel> pixels_;
};

}  // namespace penumbra
