#include "renderer/materials/plastic.h"

#include <algorithm>
#include <cmath>

#include "renderer/materials/fresnel.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

PlasticBsdf::PlasticBsdf(const PlasticParams& params, const CoatingTables& tables)
    : eta_(params.ior),
      smooth_(roughness_to_alpha(params.roughness) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(params.roughness)),
      tables_(&tables),
      internal_reflectance_(tables.internal_reflectance),
      diffuse_scale_(tables.diffuse_scale) {
  set_color(params.color);
}

const CoatingTables& PlasticBsdf::tables_for(const PlasticParams& params, CoatingTableCache& cache) {
  const float alpha = roughness_to_alpha(params.roughness);
  return cache.get(alpha < kMinMicrofacetAlpha, GgxDistribution(alpha), params.ior);
}

PlasticBsdf PlasticBsdf::with_color(const Spectrum& color) const {
  PlasticBsdf b = *this;
  b.set_color(color);
  return b;
}

void PlasticBsdf::set_color(const Spectrum& color) {
  color_ = color;
  // Steer samples between coating and base by their mean reflectances (coating reflectance 1),
  // as Mitsuba does, so the integrator sees the same sampling weights. Only the variance depends
  // on them: every sample is weighted by eval / pdf (or F / P(coating) for the Dirac lobe).
  // (Mitsuba takes a textured base's mean over the whole texture; the colour at the hit steers
  // better and changes nothing but the noise.)
  const float d_mean = (color_.x + color_.y + color_.z) / 3.f;
  specular_sampling_weight_ = 1.f / (d_mean + 1.f);
}

float PlasticBsdf::external_transmittance(float cos_theta) const {
  if (smooth_) return 1.f - fresnel_dielectric(cos_theta, eta_).reflectance;
  // Linear interpolation between the table's nodes.
  const float mu = std::clamp(cos_theta, 0.f, 1.f);
  const float* cosines = tables_->cosines.data();
  const int i = tables_->interval(mu);
  // Nodes coincide where the critical cosine rounds to 1 (ior < ~3e-4).
  const float width = cosines[i + 1] - cosines[i];
  const float w = width > 0.f ? (mu - cosines[i]) / width : 1.f;
  return (1.f - w) * tables_->transmittance[i] + w * tables_->transmittance[i + 1];
}

float PlasticBsdf::specular_probability(const BsdfContext& ctx, float cos_i,
                                        std::optional<float> transmittance_i) const {
  const bool has_spec = ctx.lobes & coating_lobe();
  const bool has_diff = ctx.lobes & kLobeDiffuseReflection;
  if (has_spec != has_diff) return has_spec ? 1.f : 0.f;
  if (!has_spec) return 0.f;
  // Coating reflectance: F(cos_i) for the smooth coating, 1 - t(cos_i) for the rough one.
  const float t_i = transmittance_i ? *transmittance_i : external_transmittance(cos_i);
  const float p_spec = (1.f - t_i) * specular_sampling_weight_;
  const float p_diff = t_i * (1.f - specular_sampling_weight_);
  return p_spec + p_diff > 0.f ? p_spec / (p_spec + p_diff) : 0.f;
}

template <bool kEval, bool kPdf>
BsdfEvalPdf PlasticBsdf::evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  BsdfEvalPdf r;
  if (wi.z <= 0.f || wo.z <= 0.f) return r;
  const bool has_diff = ctx.lobes & kLobeDiffuseReflection;
  const bool rough_coating = !smooth_ && (ctx.lobes & kLobeGlossyReflection);
  // The coating's transmittance towards wi: a factor of the base's value, and what the lobe
  // choice weighs when both lobes are enabled.
  std::optional<float> t_i;
  if (has_diff && (kEval || (ctx.lobes & coating_lobe()))) t_i = external_transmittance(wi.z);
  float p_spec = 0.f;
  if constexpr (kPdf) p_spec = specular_probability(ctx, wi.z, t_i);
  // The rough coating's half vector, D and G1(wi), shared by value and density (p_spec > 0
  // implies the glossy lobe is enabled).
  vec3 h(0.f);
  float d = 0.f, g1_i = 0.f;
  if (rough_coating && (kEval || p_spec > 0.f)) {
    h = glm::normalize(wi + wo);
    d = distr_.ndf(h);
    g1_i = distr_.smith_g1(wi, h);
  }
  if constexpr (kEval) {
    if (rough_coating) {
      // Rough coating: Walter et al. 2007 eq. 20 with the dielectric Fresnel term, G = G1 G1.
      const float f = fresnel_dielectric(glm::dot(wi, h), eta_).reflectance;
      const float spec = f * d * (g1_i * distr_.smith_g1(wo, h)) / (4.f * wi.z);
      if (std::isfinite(spec)) r.f += Spectrum(spec);
    }
    if (has_diff) {
      const float t = *t_i * external_transmittance(wo.z);
      r.f += color_ * (t * diffuse_scale_ * kInvPi * wo.z);
    }
  }
  if constexpr (kPdf) {
    const float p_diff = has_diff ? 1.f - p_spec : 0.f;
    float p = p_diff * cosine_hemisphere_pdf(wo);
    if (!smooth_ && p_spec > 0.f) {
      // Visible-normal density times the reflection Jacobian 1 / (4 wo.h); wi.h = wo.h cancels.
      const float ps = d * g1_i / (4.f * wi.z);
      if (std::isfinite(ps)) p += p_spec * ps;
    }
    r.pdf = p;
  }
  return r;
}

Spectrum PlasticBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, false>(ctx, wi, wo).f;
}

float PlasticBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<false, true>(ctx, wi, wo).pdf;
}

BsdfEvalPdf PlasticBsdf::eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, true>(ctx, wi, wo);
}

std::optional<BsdfSample> PlasticBsdf::sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                              const vec2& u) const {
  if (wi.z <= 0.f) return std::nullopt;
  const bool has_spec = ctx.lobes & coating_lobe();
  const bool has_diff = ctx.lobes & kLobeDiffuseReflection;
  if (!has_spec && !has_diff) return std::nullopt;
  const float p_spec = specular_probability(ctx, wi.z);
  const bool pick_spec = u_lobe < p_spec;

  BsdfSample bs;
  bs.eta = 1.f;
  if (smooth_ && pick_spec) {
    // Dirac reflection off the coating: weight F / P(choose coating).
    bs.wo = reflect_local(wi);
    bs.pdf = 0.f;
    bs.lobe = kLobeDeltaReflection;
    bs.weight = Spectrum(fresnel_dielectric(wi.z, eta_).reflectance / p_spec);
    return bs;
  }
  if (pick_spec) {
    const vec3 m = distr_.sample_visible(wi, u);
    bs.wo = reflect(wi, m);
    bs.lobe = kLobeGlossyReflection;
  } else {
    bs.wo = square_to_cosine_hemisphere(u);
    bs.lobe = kLobeDiffuseReflection;
  }
  if (bs.wo.z <= 0.f) return std::nullopt;
  // One-sample MIS over the lobes: pdf is the mixture density, weight eval / pdf.
  const BsdfEvalPdf ep = eval_pdf(ctx, wi, bs.wo);
  bs.pdf = ep.pdf;
  if (!(bs.pdf > 0.f)) return std::nullopt;
  bs.weight = ep.f / bs.pdf;
  if (!is_finite(bs.weight)) return std::nullopt;
  return bs;
}

}  // namespace penumbra
