#include "renderer/render/film.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

Film::Film(int width, int height)
    : width_(width), height_(height), pixels_(size_t(width) * size_t(height)) {}

double Film::relative_deviation(int x, int y) const {
  const Pixel& p = pixels_[size_t(y) * width_ + x];
  if (p.n < 2) return INFINITY;
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double m = p.sum[c] / p.n;
    const double v = std::max(0.0, (p.sum_sq[c] - p.n * m * m) / (p.n - 1));
    sum += v / (m * m + kRelativeFloor);
  }
  return std::sqrt(sum / 3.0);
}

Image Film::resolve() const {
  Image img(width_, height_);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    for (int c = 0; c < 3; ++c) img.rgb[3 * i + c] = p.n ? float(p.sum[c] / p.n) : 0.f;
  }
  return img;
}

Image Film::resolve_variance() const {
  Image img(width_, height_);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    for (int c = 0; c < 3; ++c) {
      if (p.n < 2) continue;
      const double m = p.sum[c] / p.n;
      const double v = std::max(0.0, (p.sum_sq[c] - p.n * m * m) / (p.n - 1));
      img.rgb[3 * i + c] = float(v / p.n);
    }
  }
  return img;
}

}  // namespace penumbra
