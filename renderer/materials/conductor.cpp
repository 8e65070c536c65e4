#include "renderer/materials/conductor.h"

#include "renderer/materials/fresnel.h"

namespace penumbra {

ConductorBsdf::ConductorBsdf(const Spectrum& color, float roughness)
    : color_(color),
      smooth_(roughness_to_alpha(roughness) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(roughness)) {}

template <bool kEval, bool kPdf>
BsdfEvalPdf ConductorBsdf::evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  BsdfEvalPdf r;
  if (smooth_ || !(ctx.lobes & kLobeGlossyReflection) || wi.z <= 0.f || wo.z <= 0.f) return r;
  const vec3 h = glm::normalize(wi + wo);
  // Shared by value and density: D(h), G1(wi, h) and the 4 cos_i of both denominators.
  const float d = distr_.ndf(h);
  const float g1_i = distr_.smith_g1(wi, h);
  const float denom = 4.f * wi.z;
  if constexpr (kEval) {
    // Torrance-Sparrow / Walter et al. 2007 eq. 20, times cos(theta_o):
    // f cos_o = F D G / (4 cos_i), with G = G1(wi, h) G1(wo, h) (microfacet.h).
    const float value = d * (g1_i * distr_.smith_g1(wo, h)) / denom;
    if (std::isfinite(value)) r.f = color_ * value;
  }
  if constexpr (kPdf) {
    if (glm::dot(wo, h) > 0.f) {
      // Visible-normal density times the reflection Jacobian 1 / (4 |wo.h|) (Walter et al. 2007
      // eq. 14); wi.h = wo.h cancels against the |wi.h| of the visible-normal density.
      const float p = d * g1_i / denom;
      if (std::isfinite(p)) r.pdf = p;
    }
  }
  return r;
}

Spectrum ConductorBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, false>(ctx, wi, wo).f;
}

float ConductorBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<false, true>(ctx, wi, wo).pdf;
}

BsdfEvalPdf ConductorBsdf::eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, true>(ctx, wi, wo);
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
