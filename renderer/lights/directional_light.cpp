#include "renderer/lights/directional_light.h"

namespace penumbra {

bool DirectionalLight::sample(const vec3&, float, const vec2&, LightSample* out) const {
  out->wi = -direction_;
  out->distance = kInfinity;
  out->value = irradiance_;
  out->pdf = 1.f;
  out->is_delta = true;
  return true;
}

}  // namespace penumbra
