#pragma once
// An isotropic point light of intensity I (W/sr): irradiance I cos / d^2.
#include "renderer/lights/light.h"

namespace penumbra {

class PointLight final : public Light {
 public:
  PointLight(const vec3& position, const Spectrum& intensity)
      : position_(position), intensity_(intensity) {}

  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  float power(float) const override { return 4.f * kPi * luminance(intensity_); }
  const vec3& position() const { return position_; }
  // A point shining every way.
  std::optional<LightBounds> place() const override {
    LightBounds b;
    b.bounds.extend(position_);
    return b;
  }
  const Spectrum& intensity() const { return intensity_; }

 private:
  vec3 position_;
  Spectrum intensity_;
};

}  // namespace penumbra
