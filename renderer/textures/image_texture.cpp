#include "renderer/textures/image_texture.h"

#include <algorithm>

#include "renderer/core/lane.h"
#include "renderer/core/simd_clones.h"
#include "renderer/io/image_io.h"
#include "renderer/textures/texture_image_cache.h"

namespace penumbra {
namespace {

// Texel positions are kept within +-2^30 before they become integers: the index and its
// neighbour then fit an int, and a uv that far out has no fractional precision left anyway.
// A non-finite uv (never produced by the shapes) reads texel 0 rather than overflowing.
constexpr float kMaxTexelPosition = 1073741824.f;

inline int wrap_index(int i, int size, TextureWrap wrap) {
  if (unsigned(i) < unsigned(size)) return i;  // inside: most lookups, and no division
  if (wrap == TextureWrap::kClamp) return std::clamp(i, 0, size - 1);
  const int m = i % size;
  return m < 0 ? m + size : m;
}

// The texel position p, clamped to +-kMaxTexelPosition, or 0 if not finite: std::clamp's
// comparisons as selects and the finiteness test in integer arithmetic (lane.h), so that the
// SIMD lanes below vectorise it and eval computes the same values with it.
[[gnu::always_inline]] inline float finite_position(float p) {
  const float clamped =
      when(mask(p < -kMaxTexelPosition), -kMaxTexelPosition,
           when(mask(kMaxTexelPosition < p), kMaxTexelPosition, p));
  return when(lane::finite(p), clamped, 0.f);
}

// Texels t00 (upper left), t10 (right), t01 (below) and t11 weighted by (ax, ay).
[[gnu::always_inline]] inline float bilinear(float ax, float ay, float t00, float t10, float t01,
                                             float t11) {
  const float top = (1.f - ax) * t00 + ax * t10;
  const float bottom = (1.f - ax) * t01 + ax * t11;
  return (1.f - ay) * top + ay * bottom;
}

constexpr size_t kChunk = 64;  // lanes per pass of eval_many (its arrays live on the stack)

// The bilinear lookup's texel coordinates: the upper-left texel (ix, iy) of each lane and the
// weights (ax, ay) of the right and lower ones, as eval computes them.
PENUMBRA_SIMD_CLONES
void bilinear_coordinates(size_t n, const float* __restrict u, const float* __restrict v, float w,
                          float h, float* __restrict ax, float* __restrict ay,
                          int32_t* __restrict ix, int32_t* __restrict iy) {
  for (size_t i = 0; i < n; ++i) {
    const float px = finite_position(u[i] * w - 0.5f);
    const float py = finite_position(v[i] * h - 0.5f);
    const float fx = std::floor(px), fy = std::floor(py);
    ax[i] = px - fx;
    ay[i] = py - fy;
    ix[i] = int32_t(fx);
    iy[i] = int32_t(fy);
  }
}

// The nearest lookup's texel of each lane, before wrapping.
PENUMBRA_SIMD_CLONES
void nearest_coordinates(size_t n, const float* __restrict u, const float* __restrict v, float w,
                         float h, int32_t* __restrict ix, int32_t* __restrict iy) {
  for (size_t i = 0; i < n; ++i) {
    ix[i] = int32_t(std::floor(finite_position(u[i] * w)));
    iy[i] = int32_t(std::floor(finite_position(v[i] * h)));
  }
}

// eval's blend of the four texels of each lane.
PENUMBRA_SIMD_CLONES
void bilinear_blend(size_t n, const float* __restrict ax, const float* __restrict ay,
                    const float* __restrict t00, const float* __restrict t10,
                    const float* __restrict t01, const float* __restrict t11,
                    float* __restrict out) {
  for (size_t i = 0; i < n; ++i) {
    out[i] = bilinear(ax[i], ay[i], t00[i], t10[i], t01[i], t11[i]);
  }
}

}  // namespace

void ImageLookup::eval_many(size_t n, const float* u, const float* v, int first, int count,
                            float* const* out) const {
  const int w = image_->width(), h = image_->height();
  alignas(64) float ax[kChunk], ay[kChunk], t[4][4][kChunk];
  alignas(64) int32_t ix[kChunk], iy[kChunk];
  for (size_t start = 0; start < n; start += kChunk) {
    const size_t m = std::min(kChunk, n - start);
    if (filter_ == TextureFilter::kNearest) {
      nearest_coordinates(m, u + start, v + start, float(w), float(h), ix, iy);
      for (size_t i = 0; i < m; ++i) {
        float texel[4];
        image_->fetch(wrap_index(ix[i], w, wrap_), wrap_index(iy[i], h, wrap_), first, count,
                      texel);
        for (int c = 0; c < count; ++c) out[c][start + i] = texel[c];
      }
      continue;
    }
    bilinear_coordinates(m, u + start, v + start, float(w), float(h), ax, ay, ix, iy);
    for (size_t i = 0; i < m; ++i) {
      const int x0 = wrap_index(ix[i], w, wrap_), x1 = wrap_index(ix[i] + 1, w, wrap_);
      const int y0 = wrap_index(iy[i], h, wrap_), y1 = wrap_index(iy[i] + 1, h, wrap_);
      float texel[4][4];
      image_->fetch(x0, y0, first, count, texel[0]);
      image_->fetch(x1, y0, first, count, texel[1]);
      image_->fetch(x0, y1, first, count, texel[2]);
      image_->fetch(x1, y1, first, count, texel[3]);
      for (int k = 0; k < 4; ++k)
        for (int c = 0; c < count; ++c) t[c][k][i] = texel[k][c];
    }
    for (int c = 0; c < count; ++c)
      bilinear_blend(m, ax, ay, t[c][0], t[c][1], t[c][2], t[c][3], out[c] + start);
  }
}

void ImageSpectrumTexture::eval_many(size_t n, const float* u, const float* v, float* r, float* g,
                                     float* b) const {
  if (grey_) {
    float* const out[1] = {r};
    lookup_.eval_many(n, u, v, 0, 1, out);
    std::copy(r, r + n, g);
    std::copy(r, r + n, b);
    return;
  }
  float* const out[3] = {r, g, b};
  lookup_.eval_many(n, u, v, 0, 3, out);
}

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
    out[c] = bilinear(ax, ay, t00[c], t10[c], t01[c], t11[c]);
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

void ImageFloatTexture::eval_many(size_t n, const float* u, const float* v, float* out) const {
  float* const outs[1] = {out};
  lookup_.eval_many(n, u, v, channel_, 1, outs);
}

float ImageFloatTexture::mean() const { return lookup_.image().mean(channel_); }

std::unique_ptr<ImageSpectrumTexture> make_spectrum_texture(const ImageTextureDesc& desc,
                                                            TextureImageCache& images) {
  return std::make_unique<ImageSpectrumTexture>(images.get(desc), desc.wrap,
                                                desc.filter);
}

std::unique_ptr<ImageFloatTexture> make_float_texture(const ImageTextureDesc& desc,
                                                      TextureImageCache& images) {
  const TextureImage& image = images.get(desc);
  if (desc.channel < 0 || desc.channel >= image.channels())
    throw ImageIoError(desc.path + ": has no channel " + std::to_string(desc.channel) +
                       " (it has " + std::to_string(image.channels()) + ")");
  return std::make_unique<ImageFloatTexture>(image, desc.channel, desc.wrap, desc.filter);
}

}  // namespace penumbra
