#include "renderer/shapes/sphere_shape.h"

#include "renderer/core/frame.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

float intersect_sphere(const vec3& center, float radius, const vec3& origin, const vec3& dir,
                       float t_max) {
  const vec3 f = origin - center;
  const float b = -glm::dot(f, dir);
  const vec3 l = f + b * dir;  // closest approach of the line to the centre
  const float r2 = radius * radius;
  const float disc = r2 - glm::dot(l, l);
  if (disc < 0.f) return -1.f;
  const float c = glm::dot(f, f) - r2;
  const float q = b + std::copysign(std::sqrt(disc), b);
  float t0 = q != 0.f ? c / q : 0.f;
  float t1 = q;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > 0.f && t0 < t_max) return t0;
  if (t1 > 0.f && t1 < t_max) return t1;
  return -1.f;
}

void sphere_hit_geometry(const vec3& center, float radius, const vec3& p_approx, SurfaceHit* hit) {
  vec3 d = p_approx - center;
  const float len = glm::length(d);
  const vec3 n = len > 0.f ? d / len : vec3(0.f, 0.f, 1.f);
  hit->p = center + n * radius;
  // Error of centre + radius*n after re-projection (pbrt-v4 eq. 6.16 bounds the re-projected
  // point by gamma(5)|p| about the centre); the addition of the centre adds gamma(1)|p|.
  hit->p_error = gamma_bound(6) * (glm::abs(center) + glm::abs(n * radius));
  hit->ng = n;
  hit->ns = n;
}

ShapeSample sample_sphere(const vec3& center, float radius, const vec3& ref, const vec2& u) {
  ShapeSample s;
  const vec3 to_center = center - ref;
  const float dc2 = glm::dot(to_center, to_center);
  const float r2 = radius * radius;
  if (dc2 <= r2 * 1.0001f) {
    // Inside (or on) the sphere: uniform area sampling.
    const vec3 n = square_to_uniform_sphere(u);
    s.p = center + radius * n;
    s.n = n;
    s.p_error = gamma_bound(6) * (glm::abs(center) + glm::abs(n * radius));
    const vec3 w = s.p - ref;
    const float dist2 = glm::dot(w, w);
    const float cos_l = std::abs(glm::dot(n, w)) / std::sqrt(dist2);
    const float area = 4.f * kPi * r2;
    s.pdf = cos_l > 0.f ? dist2 / (cos_l * area) : 0.f;
    return s;
  }
  const float dc = std::sqrt(dc2);
  const vec3 wc = to_center / dc;
  const Frame frame(wc);
  const float sin2_max = r2 / dc2;
  const float cos_max = safe_sqrt(1.f - sin2_max);
  // For tiny or distant spheres 1 - cos_max cancels catastrophically; its series is exact enough.
  const float one_minus_cos_max = sin2_max < 1e-3f ? sin2_max * 0.5f + sin2_max * sin2_max / 8.f
                                                   : 1.f - cos_max;
  const float cos_t = 1.f - u.x * one_minus_cos_max;
  const float sin2_t = std::max(0.f, 1.f - cos_t * cos_t);
  const float sin2_t_exact = u.x * one_minus_cos_max * (2.f - u.x * one_minus_cos_max);
  const float sin2 = sin2_max < 1e-3f ? sin2_t_exact : sin2_t;
  // Angle alpha at the centre between -wc and the sampled point, by the law of cosines in the
  // triangle (ref, centre, point) (pbrt-v3 section 14.2.2).
  const float ds = dc * cos_t - safe_sqrt(r2 - dc2 * sin2);
  const float ca = std::clamp((dc2 + r2 - ds * ds) / (2.f * dc * radius), -1.f, 1.f);
  const float sa = safe_sqrt(1.f - ca * ca);
  const float phi = 2.f * kPi * u.y;
  const vec3 n_local(sa * std::cos(phi), sa * std::sin(phi), ca);
  const vec3 n = -frame.to_world(n_local);
  s.n = glm::normalize(n);
  s.p = center + radius * s.n;
  s.p_error = gamma_bound(6) * (glm::abs(center) + glm::abs(s.n * radius));
  s.pdf = 1.f / (2.f * kPi * one_minus_cos_max);
  return s;
}

float sphere_pdf(const vec3& center, float radius, const vec3& ref, const vec3& p, const vec3& n) {
  const vec3 to_center = center - ref;
  const float dc2 = glm::dot(to_center, to_center);
  const float r2 = radius * radius;
  if (dc2 <= r2 * 1.0001f) {
    const vec3 w = p - ref;
    const float dist2 = glm::dot(w, w);
    const float cos_l = std::abs(glm::dot(n, w)) / std::sqrt(dist2);
    return cos_l > 0.f ? dist2 / (cos_l * 4.f * kPi * r2) : 0.f;
  }
  const float sin2_max = r2 / dc2;
  const float one_minus_cos_max =
      sin2_max < 1e-3f ? sin2_max * 0.5f + sin2_max * sin2_max / 8.f : 1.f - safe_sqrt(1.f - sin2_max);
  return 1.f / (2.f * kPi * one_minus_cos_max);
}

}  // namespace penumbra
