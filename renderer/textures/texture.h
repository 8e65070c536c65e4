#pragma once
// Textures: a value evaluated at a surface point (pbrt-v4 textures.h, Mitsuba 3 Texture). Image
// textures (image_texture.h) implement these interfaces; materials and emitters look them up per
// hit. A constant parameter stays a plain value in the material (no texture object, no virtual
// call); ConstantSpectrumTexture / ConstantFloatTexture exist for code that wants any texture.
//
// Adding a texture: a file pair here deriving from SpectrumTexture or FloatTexture, one line
// where the scene build turns its input into the class, and its tests (docs/architecture.md).
#include "renderer/core/math.h"

namespace penumbra {

// Where a texture is looked up.
struct TextureQuery {
  vec3 p{0.f};   // world-space point
  vec2 uv{0.f};  // surface coordinates; (0, 0) is an image's top-left corner
  float time = 0.f;  // normalised shutter time
};

class SpectrumTexture {
 public:
  virtual ~SpectrumTexture() = default;
  virtual Spectrum eval(const TextureQuery& q) const = 0;
  // The mean over the texture's domain (e.g. an emitter's power estimate).
  virtual Spectrum mean() const = 0;
};

class FloatTexture {
 public:
  virtual ~FloatTexture() = default;
  virtual float eval(const TextureQuery& q) const = 0;
  virtual float mean() const = 0;
};

}  // namespace penumbra
