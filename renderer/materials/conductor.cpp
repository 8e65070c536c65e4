#include "renderer/materials/conductor.h"

#include "renderer/materials/fresnel.h"

namespace penumbra {

ConductorBsdf::ConductorBsdf(const Spectrum& color, float roughness)
    : color_(color),
      smooth_(roughness_to_alpha(roughness) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(roughness)) {}

Spectrum ConductorBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (smooth_ || !(ctx.lobes & kLobeGlossyReflection) || wi.z <= 0.f || wo.z <= 0.f)
    return Spectrum(0.f);
  const vec3 h = glm::normalize(wi + wo);
  // Torrance-Sparrow / Walter et al. 2007 eq. 20, times cos(theta_o):
  // f cos_o = F D G / (4 cos_i).
  const float value = distr_.ndf(h) * distr_.smith_g(wi, wo, h) / (4.f * wi.z);
  return std::isfinite(value) ? color_ * value : Spectrum(0.f);
}

float ConductorBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (smooth_ || !(ctx.lobes & kLobeGlossyReflection) || wi.z <= 0.f || wo.z <= 0.f) return 0.f;
  const vec3 h = glm::normalize(wi + wo);
  if (glm::dot(wo, h) <= 0.f) return 0.f;
  // Visible-normal density times the reflection Jacobian 1 / (4 |wo.h|) (Walter et al. 2007
  // eq. 14); wi.h = wo.h cancels against the |wi.h| of the visible-normal density.
  const float p = distr_.ndf(h) * distr_.smith_g1(wi, h) / (4.f * wi.z);
  return std::isfinite(p) ? p : 0.f;
}

std::optional<BsdfSample> ConductorBsdf::sample(const BsdfContext& ctx, const vec3& wi, float,
                                                const vec2& u) const {
  if (wi.z <= 0.f) return std::nullopt;
  BsdfSample bs;
  bs.eta = 1.f;
  if (smooth_) {
    if (!(ctx.lobes & kLobeDeltaReflection)) return std::nullopt;
    bs.wo = reflect_local(wi);
    bs.weight = color_;
    bs.pdf = 0.f;
    bs.lobe = kLobeDeltaReflection;
    return bs;
  }
  if (!(ctx.lobes & kLobeGlossyReflection)) return std::nullopt;
  const vec3 m = distr_.sample_visible(wi, u);
  bs.wo = reflect(wi, m);
  if (bs.wo.z <= 0.f) return std::nullopt;
  const float dot_wo_m = glm::dot(bs.wo, m);
  bs.pdf = distr_.pdf_visible(wi, m) / (4.f * dot_wo_m);
  if (!(bs.pdf > 0.f) || !std::isfinite(bs.pdf)) return std::nullopt;
  // eval / pdf = F G1(wi) G1(wo) / G1(wi) = F G1(wo) (Heitz 2014, eq. 19).
  const float g1 = distr_.smith_g1(bs.wo, m);
  if (!(g1 > 0.f)) return std::nullopt;
  bs.weight = color_ * g1;
  bs.lobe = kLobeGlossyReflection;
  return bs;
}

}  // namespace penumbra
