#include "renderer/shapes/shape.h"

namespace penumbra {

float area_to_solid_angle(const vec3& ref, const vec3& p, const vec3& n, float area) {
  const vec3 w = p - ref;
  const float dist2 = glm::dot(w, w);
  const float cos_l = std::abs(glm::dot(n, w)) / std::sqrt(dist2);
  return cos_l > 0.f && area > 0.f ? dist2 / (cos_l * area) : 0.f;
}

}  // namespace penumbra
