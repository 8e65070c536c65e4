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
