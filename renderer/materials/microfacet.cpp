#include "renderer/materials/microfacet.h"

#include "renderer/materials/fresnel.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

float GgxDistribution::ndf(const vec3& m) const {
  // Walter et al. 2007 eq. 33 written without trigonometry:
  // D = 1 / (pi a^2 ((m.x^2 + m.y^2) / a^2 + m.z^2)^2).
  const float a2 = alpha_ * alpha_;
  const float t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
  const float d = 1.f / (kPi * a2 * t * t);
  // Drop vanishing values (and m.z <= 0) so later divisions stay finite.
  return (m.z > 0.f && d * m.z > 1e-20f && std::isfinite(d)) ? d : 0.f;
}

float GgxDistribution::smith_g1(const vec3& v, const vec3& m) const {
  if (glm::dot(v, m) * v.z <= 0.f) return 0.f;
  const float xy_a2 = alpha_ * alpha_ * (v.x * v.x + v.y * v.y);
  if (xy_a2 == 0.f) return 1.f;
  // Walter et al. 2007 eq. 34: G1 = 2 / (1 + sqrt(1 + a^2 tan^2 theta_v)).
  const float tan2_a2 = xy_a2 / (v.z * v.z);
  return 2.f / (1.f + std::sqrt(1.f + tan2_a2));
}

vec3 GgxDistribution::sample_visible(const vec3& wi, const vec2& u) const {
  // Heitz 2018, listing 1: stretch the view vector to the alpha = 1 configuration, sample the
  // projected hemisphere (a disk whose far half is squeezed by (1 + V.z) / 2), unstretch.
  const StretchedView f = stretched_view(alpha_, wi);
  // The concentric map keeps the stratification of low-discrepancy samples (Heitz uses polar).
  const vec2 p = square_to_disk_concentric(u);
  const float p1 = p.x;
  const float p2 = (1.f - f.s) * safe_sqrt(1.f - p1 * p1) + f.s * p.y;
  const vec3 nh = p1 * f.t1 + p2 * f.t2 + safe_sqrt(1.f - p1 * p1 - p2 * p2) * f.vh;
  return glm::normalize(vec3(alpha_ * nh.x, alpha_ * nh.y, std::max(0.f, nh.z)));
}

namespace {

// Integrates fn(m, wi) over the visible-normal distribution of wi with a tensor Gauss-Legendre
// rule on the unit square of sample_visible's input.
template <typename Fn>
float integrate_visible_normals(const GgxDistribution& distr, float cos_i, int res, Fn fn) {
  std::vector<double> nodes, weights;
  gauss_legendre(res, nodes, weights);
  const float c = std::clamp(cos_i, 1e-6f, 1.f);
  const vec3 wi(std::sqrt(std::max(0.f, 1.f - c * c)), 0.f, c);
  double sum = 0.0;
  for (int a = 0; a < res; ++a) {
    for (int b = 0; b < res; ++b) {
      const vec2 u(float(0.5 * nodes[a] + 0.5), float(0.5 * nodes[b] + 0.5));
      const vec3 m = distr.sample_visible(wi, u);
      sum += 0.25 * weights[a] * weights[b] * fn(wi, m);
    }
  }
  return float(sum);
}

}  // namespace

float rough_dielectric_reflectance(const GgxDistribution& distr, float cos_i, float eta) {
  // 64^2 Gauss-Legendre nodes (Mitsuba 3 uses 128^2 for the internal case): a fraction of a
  // percent on the averaged reflectance for a 4x faster table (docs/design-notes.md).
  const int res = eta > 1.f ? 32 : 64;
  return integrate_visible_normals(distr, cos_i, res, [&](const vec3& wi, const vec3& m) {
    const vec3 wo = reflect(wi, m);
    if (wo.z <= 0.f) return 0.f;
    return fresnel_dielectric(glm::dot(wi, m), eta).reflectance * distr.smith_g1(wo, m);
  });
}

float rough_dielectric_transmittance(const GgxDistribution& distr, float cos_i, float eta) {
  const int res = eta > 1.f ? 32 : 64;
  return integrate_visible_normals(distr, cos_i, res, [&](const vec3& wi, const vec3& m) {
    const FresnelDielectric fr = fresnel_dielectric(glm::dot(wi, m), eta);
    if (fr.reflectance >= 1.f) return 0.f;
    const vec3 wo = refract(wi, m, fr.cos_t, fr.eta_ti);
    if (wo.z * wi.z >= 0.f) return 0.f;
    return (1.f - fr.reflectance) * distr.smith_g1(wo, m);
  });
}

}  // namespace penumbra
