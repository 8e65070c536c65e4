#pragma once
// A distant light from one direction, given by the irradiance E (W/m^2) on a surface facing it.
#include "renderer/lights/light.h"

namespace penumbra {

class DirectionalLight final : public Light {
 public:
  // `direction`: the way the light travels (normalised here).
  DirectionalLight(const vec3& direction, const Spectrum& irradiance)
      : direction_(glm::normalize(direction)), irradiance_(irradiance) {}

  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  // E times the area of the scene's bounding disc (pbrt-v4 DistantLight::Phi).
  float power(float scene_radius) const override {
    return luminance(irradiance_) * kPi * (scene_radius * scene_radius);
  }
  const vec3& direction() const { return direction_; }  // normalised
  const Spectrum& irradiance() const { return irradiance_; }

 private:
  vec3 direction_;
  Spectrum irradiance_;
};

}  // namespace penumbra
