#pragma once
// Textures: a value evaluated at a surface point (pbrt-v4 textures.h, Mitsuba 3 Texture). Today
// every material parameter is a constant; image textures (the asset issue) implement the same
// interfaces, and materials will evaluate them per hit.
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
};

class FloatTexture {
 public:
  virtual ~FloatTexture() = default;
  virtual float eval(const TextureQuery& q) const = 0;
};

}  // namespace penumbra
