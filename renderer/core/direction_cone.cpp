#include "renderer/core/direction_cone.h"

#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

// v rotated by `angle` about the unit axis k (Rodrigues).
vec3 rotate(const vec3& v, const vec3& k, float angle) {
  const float c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(k, v) * s + k * (glm::dot(k, v) * (1.f - c));
}

}  // namespace

DirectionCone DirectionCone::merge(const DirectionCone& a, const DirectionCone& b) {
  if (a.cos_theta <= -1.f || b.cos_theta <= -1.f) return whole_sphere();
  const float theta_a = safe_acos(a.cos_theta), theta_b = safe_acos(b.cos_theta);
  const float theta_d = safe_acos(glm::dot(a.axis, b.axis));
  if (std::min(theta_d + theta_b, kPi) <= theta_a) return a;
  if (std::min(theta_d + theta_a, kPi) <= theta_b) return b;
  const float theta_o = 0.5f * (theta_a + theta_d + theta_b);
  if (theta_o >= kPi) return whole_sphere();
  const vec3 k = glm::cross(a.axis, b.axis);
  const float k_len = glm::length(k);
  if (!(k_len > 1e-7f)) return whole_sphere();  // opposite axes (equal ones returned above)
  DirectionCone out;
  out.axis = glm::normalize(rotate(a.axis, k / k_len, theta_o - theta_a));
  out.cos_theta = std::cos(theta_o);
  // Rounding may leave either input's edge a hair outside: widen by a few ulps' worth.
  out.cos_theta = std::max(-1.f, out.cos_theta - 1e-5f);
  return out;
}

}  // namespace penumbra
