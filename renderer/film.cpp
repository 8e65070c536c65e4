#include "renderer/film.h"

namespace penumbra {

Film::Film(int width, int height)
    : width_(width), height_(height), pixels_(size_t(width) * size_t(height)) {}

double Film::relative_error(int x, int y) const {
  const Pixel& p = pixels_[size_t(y) * width_ + x];
  if (p.n < 2) return INFINITY;
  const double w[3] = {0.2126, 0.7152, 0.0722};
  double mean = 0.0, var = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double m = p.sum[c] / p.n;
    const double v = std::max(0.0, (p.sum_sq[c] - p.n * m * m) / (p.n - 1));
    mean += w[c] * m;
    var += w[c] * w[c] * v;  // channels treated as independent: a conservative estimate
  }
  // Cycles-style: error relative to the mean, with a floor so near-black pixels converge.
  return std::sqrt(var / p.n) / std::max(mean, 1e-3);
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
