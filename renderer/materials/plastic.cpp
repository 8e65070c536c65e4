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

float PlasticBsdf::specular_probability(const BsdfContext& ctx, float cos_i) const {
  const bool has_spec = ctx.lobes & coating_lobe();
  const bool has_diff = ctx.lobes & kLobeDiffuseReflection;
  if (has_spec != has_diff) return has_spec ? 1.f : 0.f;
  if (!has_spec) return 0.f;
  // Coating reflectance: F(cos_i) for the smooth coating, 1 - t(cos_i) for the rough one.
  const float t_i = external_transmittance(cos_i);
  const float p_spec = (1.f - t_i) * specular_sampling_weight_;
  const float p_diff = t_i * (1.f - specular_sampling_weight_);
  return p_spec + p_diff > 0.f ? p_spec / (p_spec + p_diff) : 0.f;
}

Spectrum PlasticBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (wi.z <= 0.f || wo.z <= 0.f) return Spectrum(0.f);
  Spectrum value(0.f);
  if (!smooth_ && (ctx.lobes & kLobeGlossyReflection)) {
    // Rough coating: Walter et al. 2007 eq. 20 with the dielectric Fresnel term.
    const vec3 h = glm::normalize(wi + wo);
    const float f = fresnel_dielectric(glm::dot(wi, h), eta_).reflectance;
    const float spec = f * distr_.ndf(h) * distr_.smith_g(wi, wo, h) / (4.f * wi.z);
    if (std::isfinite(spec)) value += Spectrum(spec);
  }
  if (ctx.lobes & kLobeDiffuseReflection) {
    const float t = external_transmittance(wi.z) * external_transmittance(wo.z);
    value += color_ * (t * diffuse_scale_ * kInvPi * wo.z);
  }
  return value;
}

float PlasticBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (wi.z <= 0.f || wo.z <= 0.f) return 0.f;
  const float p_spec = specular_probability(ctx, wi.z);
  const float p_diff = (ctx.lobes & kLobeDiffuseReflection) ? 1.f - p_spec : 0.f;
  float p = p_diff * cosine_hemisphere_pdf(wo);
  if (!smooth_ && p_spec > 0.f) {
    const vec3 h = glm::normalize(wi + wo);
    // Visible-normal density times the reflection Jacobian 1 / (4 wo.h); wi.h = wo.h cancels.
    const float ps = distr_.ndf(h) * distr_.smith_g1(wi, h) / (4.f * wi.z);
    if (std::isfinite(ps)) p += p_spec * ps;
  }
  return p;
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
  bs.pdf = pdf(ctx, wi, bs.wo);
  if (!(bs.pdf > 0.f)) return std::nullopt;
  bs.weight = eval(ctx, wi, bs.wo) / bs.pdf;
  if (!is_finite(bs.weight)) return std::nullopt;
  return bs;
}

}  // namespace penumbra
