#include "renderer/lights/environment_light.h"

#include "renderer/sampling/sampling.h"

namespace penumbra {

bool ConstantEnvironment::sample(const vec3&, float, const vec2& u, LightSample* out) const {
  out->wi = square_to_uniform_sphere(u);
  out->distance = kInfinity;
  out->value = radiance_;
  out->pdf = uniform_sphere_pdf();
  out->is_delta = false;
  return true;
}

float ConstantEnvironment::pdf(const vec3&) const { return uniform_sphere_pdf(); }

}  // namespace penumbra
