#include "renderer/materials/coating_tables_integrals.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/quadrature.h"
#include "renderer/materials/fresnel.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

VisibleNormalQuadrature::VisibleNormalQuadrature(int res) : res_(res) {
  std::vector<double> x, w;
  gauss_legendre(res, x, w);
  nodes_.reserve(size_t(res) * size_t(res));
  for (int a = 0; a < res; ++a) {
    for (int b = 0; b < res; ++b) {
      // The same float input and map as GgxDistribution::sample_visible's.
      const vec2 u(float(0.5 * x[a] + 0.5), float(0.5 * x[b] + 0.5));
      const vec2 p = square_to_disk_concentric(u);
      const float slack = 1.f - p.x * p.x;
      nodes_.push_back({p.x, slack, safe_sqrt(slack), p.y, 0.25 * w[a] * w[b]});
    }
  }
}

// The generic integral (microfacet.cpp) with sample_visible (Heitz 2018, listing 1) split into
// its per-direction and per-node parts. Every float operation is the generic one's, in the same
// order, so the sum is the same to the bit (a test checks): the tables, and so the images, do
// not change.
template <typename Fn>
float VisibleNormalQuadrature::integrate(const GgxDistribution& distr, float cos_i, Fn fn) const {
  const float alpha = distr.alpha();
  const float c = std::clamp(cos_i, 1e-6f, 1.f);
  const vec3 wi(std::sqrt(std::max(0.f, 1.f - c * c)), 0.f, c);
  // Stretch to the alpha = 1 configuration and build the frame around the stretched view.
  const StretchedView f = stretched_view(alpha, wi);
  double sum = 0.0;
  for (const Node& n : nodes_) {
    // Squeeze the disk's far half by s, lift onto the hemisphere, unstretch.
    const float p2 = (1.f - f.s) * n.p1_root + f.s * n.py;
    const vec3 nh = n.p1 * f.t1 + p2 * f.t2 + safe_sqrt(n.p1_slack - p2 * p2) * f.vh;
    const vec3 m = glm::normalize(vec3(alpha * nh.x, alpha * nh.y, std::max(0.f, nh.z)));
    sum += n.weight * fn(wi, m);
  }
  return float(sum);
}

float VisibleNormalQuadrature::reflectance(const GgxDistribution& distr, float cos_i,
                                           float eta) const {
  return integrate(distr, cos_i, [&](const vec3& wi, const vec3& m) {
    const vec3 wo = reflect(wi, m);
    if (wo.z <= 0.f) return 0.f;
    return fresnel_dielectric(glm::dot(wi, m), eta).reflectance * distr.smith_g1(wo, m);
  });
}

float VisibleNormalQuadrature::transmittance(const GgxDistribution& distr, float cos_i,
                                             float eta) const {
  return integrate(distr, cos_i, [&](const vec3& wi, const vec3& m) {
    const FresnelDielectric fr = fresnel_dielectric(glm::dot(wi, m), eta);
    if (fr.reflectance >= 1.f) return 0.f;
    const vec3 wo = refract(wi, m, fr.cos_t, fr.eta_ti);
    if (wo.z * wi.z >= 0.f) return 0.f;
    return (1.f - fr.reflectance) * distr.smith_g1(wo, m);
  });
}

const VisibleNormalQuadrature& coating_quadrature(float eta) {
  // The resolutions of microfacet.cpp's rough_dielectric_* (magic statics: thread-safe).
  static const VisibleNormalQuadrature above(32), below(64);
  return eta > 1.f ? above : below;
}

}  // namespace penumbra
