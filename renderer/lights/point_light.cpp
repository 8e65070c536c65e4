#include "renderer/lights/point_light.h"

namespace penumbra {

bool PointLight::sample(const vec3& ref, float, const vec2&, LightSample* out) const {
  const vec3 d = position_ - ref;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return false;
  out->distance = std::sqrt(dist2);
  out->wi = d / out->distance;
  out->value = intensity_ / dist2;
  out->pdf = 1.f;
  out->is_delta = true;
  out->p = position_;
  out->p_error = vec3(0.f);
  out->n = vec3(0.f);  // a point in free space: no surface to offset the shadow ray from
  return true;
}

}  // namespace penumbra
