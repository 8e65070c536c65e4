#pragma once
// The same value everywhere: what every material parameter is today.
#include "renderer/textures/texture.h"

namespace penumbra {

class ConstantSpectrumTexture final : public SpectrumTexture {
 public:
  explicit ConstantSpectrumTexture(const Spectrum& value) : value_(value) {}
  Spectrum eval(const TextureQuery&) const override { return value_; }
  Spectrum mean() const override { return value_; }

 private:
  Spectrum value_;
};

class ConstantFloatTexture final : public FloatTexture {
 public:
  explicit ConstantFloatTexture(float value) : value_(value) {}
  float eval(const TextureQuery&) const override { return value_; }
  float mean() const override { return value_; }

 private:
  float value_;
};

}  // namespace penumbra
