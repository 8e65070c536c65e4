#include "renderer/textures/image_texture.h"

#include "renderer/io/image_io.h"
#include "renderer/textures/texture_image_cache.h"

namespace penumbra {
namespace {

// Texel positions are kept within +-2^30 before they become integers: the index and its
// neighbour then fit an int, and a uv that far out has no fractional precision left anyway.
// A non-finite uv (never produced by the shapes) reads texel 0 rather than overflowing.
constexpr float kMaxTexelPosition = 1073741824.f;

inline float finite_position(float p) {
  return std::isfinite(p) ? std::clamp(p, -kMaxTexelPosition, kMaxTexelPosition) : 0.f;
}

inline int wrap_index(int i, int size, TextureWrap wrap) {
  if (unsigned(i) < unsigned(size)) return i;  // inside: most lookups, and no division
  if (wrap == TextureWrap::kClamp) return std::clamp(i, 0, size - 1);
  const int m = i % size;
  return m < 0 ? m + size : m;
}

}  // namespace

void ImageLookup::eval(const vec2& uv, int first, int count, float* out) const {
  const int w = image_->width(), h = image_->height();
  if (filter_ == TextureFilter::kNearest) {
    const int x = wrap_index(int(std::floor(finite_position(uv.x * float(w)))), w, wrap_);
    const int y = wrap_index(int(std::floor(finite_position(uv.y * float(h)))), h, wrap_);
    image_->fetch(x, y, first, count, out);
    return;
  }
  // Texel centres sit at half-integers: shift by half a texel so that floor() finds the centre
  // to the upper left.
  const float px = finite_position(uv.x * float(w) - 0.5f);
  const float py = finite_position(uv.y * float(h) - 0.5f);
  const float fx = std::floor(px), fy = std::floor(py);
  const float ax = px - fx, ay = py - fy;  // weights of the right and lower texels
  const int ix = int(fx), iy = int(fy);
  const int x0 = wrap_index(ix, w, wrap_), x1 = wrap_index(ix + 1, w, wrap_);
  const int y0 = wrap_index(iy, h, wrap_), y1 = wrap_index(iy + 1, h, wrap_);
  float t00[4], t10[4], t01[4], t11[4];
  image_->fetch(x0, y0, first, count, t00);
  image_->fetch(x1, y0, first, count, t10);
  image_->fetch(x0, y1, first, count, t01);
  image_->fetch(x1, y1, first, count, t11);
  for (int c = 0; c < count; ++c) {
    const float top = (1.f - ax) * t00[c] + ax * t10[c];
    const float bottom = (1.f - ax) * t01[c] + ax * t11[c];
    out[c] = (1.f - ay) * top + ay * bottom;
  }
}

Spectrum ImageSpectrumTexture::eval(const TextureQuery& q) const {
  if (grey_) {
    float v;
    lookup_.eval(q.uv, 0, 1, &v);
    return Spectrum(v);
  }
  Spectrum rgb;
  lookup_.eval(q.uv, 0, 3, &rgb.x);
  return rgb;
}

Spectrum ImageSpectrumTexture::mean() const {
  const TextureImage& image = lookup_.image();
  if (grey_) return Spectrum(image.mean(0));
  return Spectrum(image.mean(0), image.mean(1), image.mean(2));
}

ImageFloatTexture::ImageFloatTexture(const TextureImage& image, int channel, TextureWrap wrap,
                                     TextureFilter filter)
    : lookup_(image, wrap, filter), channel_(std::clamp(channel, 0, image.channels() - 1)) {}

float ImageFloatTexture::eval(const TextureQuery& q) const {
  float v;
  lookup_.eval(q.uv, channel_, 1, &v);
  return v;
}

float ImageFloatTexture::mean() const { return lookup_.image().mean(channel_); }

std::unique_ptr<ImageSpectrumTexture> make_spectrum_texture(const ImageTextureDesc& desc,
                                                            TextureImageCache& images) {
  return std::make_unique<ImageSpectrumTexture>(images.get(desc.path, desc.colorspace), desc.wrap,
                                                desc.filter);
}

std::unique_ptr<ImageFloatTexture> make_float_texture(const ImageTextureDesc& desc,
                                                      TextureImageCache& images) {
  const TextureImage& image = images.get(desc.path, desc.colorspace);
  if (desc.channel < 0 || desc.channel >= image.channels())
    throw ImageIoError(desc.path + ": has no channel " + std::to_string(desc.channel) +
                       " (it has " + std::to_string(image.channels()) + ")");
  return std::make_unique<ImageFloatTexture>(image, desc.channel, desc.wrap, desc.filter);
}

}  // namespace penumbra
