#pragma once
// Image textures: a decoded image looked up at a surface's uv, with the conventions of
// Mitsuba 3's `bitmap` texture so that references compare. Mitsuba evaluates bitmaps through
// Dr.Jit's Texture (drjit include/drjit/texture_impl.h, tex_eval and tex_wrap):
//  * uv (0, 0) is the image's top-left corner, (1, 1) its bottom-right; texel (x, y) covers
//    [x, x + 1) / width x [y, y + 1) / height, its centre at ((x + 0.5) / width, (y + 0.5) /
//    height).
//  * bilinear: p = uv * size - 0.5, the four texels around floor(p) weighted by the fraction;
//    each corner index is wrapped on its own, so at the border a repeating image blends with
//    the opposite edge and a clamped one with itself.
//  * nearest: the texel floor(uv * size), wrapped.
//  * repeat: index mod size (Euclidean); clamp: index clamped to [0, size - 1].
// Values are linear already (sRGB decoded at load), so interpolation is in linear space, as
// Mitsuba's bitmap with raw = false.
#include <memory>

#include "renderer/textures/texture.h"
#include "renderer/textures/texture_desc.h"
#include "renderer/textures/texture_image.h"

namespace penumbra {

class TextureImageCache;

// The lookup shared by the texture kinds: `count` channels from `first` at uv into `out`.
class ImageLookup {
 public:
  ImageLookup(const TextureImage& image, TextureWrap wrap, TextureFilter filter)
      : image_(&image), wrap_(wrap), filter_(filter) {}

  void eval(const vec2& uv, int first, int count, float* out) const;
  // eval at (u[i], v[i]) for i < n, channel first + c into out[c][i]: the same values to the
  // bit, with the texel coordinates and the bilinear blend in SIMD lanes and the texel loads
  // between them in one loop (docs/performance.md, levers: "textured colours and roughnesses
  // in lanes").
  void eval_many(size_t n, const float* u, const float* v, int first, int count,
                 float* const* out) const;
  const TextureImage& image() const { return *image_; }

 private:
  const TextureImage* image_;
  TextureWrap wrap_;
  TextureFilter filter_;
};

// RGB from the first three channels; a grey image (one or two channels: Y, YA) gives its first
// channel in all three. An alpha channel is ignored.
class ImageSpectrumTexture final : public SpectrumTexture {
 public:
  ImageSpectrumTexture(const TextureImage& image, TextureWrap wrap, TextureFilter filter)
      : lookup_(image, wrap, filter), grey_(image.channels() < 3) {}

  Spectrum eval(const TextureQuery& q) const override;
  Spectrum mean() const override;  // over the image's texels
  // eval at uv (u[i], v[i]) for i < n into (r[i], g[i], b[i]), to the bit.
  void eval_many(size_t n, const float* u, const float* v, float* r, float* g, float* b) const;

 private:
  ImageLookup lookup_;
  bool grey_;
};

// One channel of the image.
class ImageFloatTexture final : public FloatTexture {
 public:
  // `channel` must exist (make_float_texture checks; out of range reads the nearest one).
  ImageFloatTexture(const TextureImage& image, int channel, TextureWrap wrap, TextureFilter filter);

  float eval(const TextureQuery& q) const override;
  float mean() const override;  // over the image's texels
  // eval at uv (u[i], v[i]) for i < n into out[i], to the bit.
  void eval_many(size_t n, const float* u, const float* v, float* out) const;

 private:
  ImageLookup lookup_;
  int channel_;
};

// The textures a description asks for, over images decoded (once) by `images`. Throw
// ImageIoError naming the file (unreadable, over the limits, or no such channel).
std::unique_ptr<ImageSpectrumTexture> make_spectrum_texture(const ImageTextureDesc& desc,
                                                            TextureImageCache& images);
std::unique_ptr<ImageFloatTexture> make_float_texture(const ImageTextureDesc& desc,
                                                      TextureImageCache& images);

}  // namespace penumbra
