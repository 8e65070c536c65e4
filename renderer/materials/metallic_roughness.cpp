#include "renderer/materials/metallic_roughness.h"

#include "renderer/materials/fresnel.h"
#include "renderer/materials/microfacet_albedo.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {
namespace {

inline float pow5(float x) {
  const float x2 = x * x;
  return x2 * x2 * x;
}

inline float mean(const Spectrum& s) { return (s.x + s.y + s.z) / 3.f; }

}  // namespace

MetallicRoughnessBsdf::MetallicRoughnessBsdf(const Spectrum& base_color, float metallic,
                                             float roughness)
    : base_color_(glm::clamp(base_color, Spectrum(0.f), Spectrum(1.f))),
      metallic_(std::clamp(metallic, 0.f, 1.f)),
      roughness_(std::clamp(roughness, 0.f, 1.f)),
      smooth_(roughness_to_alpha(roughness_) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(roughness_)) {
  if (smooth_) {
    // The mirror: E = 1 and E5 = (1 - mu)^5 exactly; 2 \int (1 - mu)^5 mu dmu = 1/21.
    e_avg_ = 1.f;
    e5_avg_ = 1.f / 21.f;
  } else {
    const MicrofacetAlbedo avg = ggx_albedo_average(roughness_);
    e_avg_ = avg.e;
    e5_avg_ = avg.e5;
  }
  dielectric_avg_ = kDielectricF0 * (e_avg_ - e5_avg_) + e5_avg_;
  // Kulla and Conty 2017: the average Schlick Fresnel f0 + (1 - f0) / 21, and the energy that
  // bounces on between microfacets, F_avg^2 E_avg / (1 - F_avg (1 - E_avg)) (a geometric series
  // of further bounces, each reflecting F_avg).
  const Spectrum f_avg = base_color_ + (Spectrum(1.f) - base_color_) / 21.f;
  f_ms_ = f_avg * f_avg * e_avg_ / (Spectrum(1.f) - f_avg * (1.f - e_avg_));
}

Spectrum MetallicRoughnessBsdf::fresnel(float cos_ih) const {
  const float w = pow5(std::clamp(1.f - cos_ih, 0.f, 1.f));
  const float dielectric = kDielectricF0 + (1.f - kDielectricF0) * w;
  const Spectrum metal = base_color_ + (Spectrum(1.f) - base_color_) * w;
  return (1.f - metallic_) * Spectrum(dielectric) + metallic_ * metal;
}

Spectrum MetallicRoughnessBsdf::specular_albedo(float mu) const {
  const MicrofacetAlbedo a =
      smooth_ ? MicrofacetAlbedo{1.f, pow5(1.f - mu)} : ggx_albedo(mu, roughness_);
  // Schlick is linear in f0: \int F s cos = f0 (E - E5) + E5.
  const float dielectric = kDielectricF0 * (a.e - a.e5) + a.e5;
  const Spectrum metal = base_color_ * (a.e - a.e5) + Spectrum(a.e5);
  return (1.f - metallic_) * Spectrum(dielectric) + metallic_ * metal;
}

Spectrum MetallicRoughnessBsdf::diffuse_value(float mu_i, float mu_o) const {
  const MicrofacetAlbedo ai =
      smooth_ ? MicrofacetAlbedo{1.f, pow5(1.f - mu_i)} : ggx_albedo(mu_i, roughness_);
  const MicrofacetAlbedo ao =
      smooth_ ? MicrofacetAlbedo{1.f, pow5(1.f - mu_o)} : ggx_albedo(mu_o, roughness_);
  Spectrum value(0.f);
  if (metallic_ < 1.f) {
    // Albedo scaling of the Lambertian base under the f0 = 0.04 specular layer.
    const float ei = kDielectricF0 * (ai.e - ai.e5) + ai.e5;
    const float eo = kDielectricF0 * (ao.e - ao.e5) + ao.e5;
    const float scale = std::max(0.f, 1.f - ei) * std::max(0.f, 1.f - eo) /
                        (kPi * std::max(1e-6f, 1.f - dielectric_avg_));
    value += (1.f - metallic_) * scale * base_color_;
  }
  if (metallic_ > 0.f && 1.f - e_avg_ > 1e-6f) {
    // Multiple scattering of the metal (Kulla and Conty 2017).
    const float scale =
        std::max(0.f, 1.f - ai.e) * std::max(0.f, 1.f - ao.e) / (kPi * (1.f - e_avg_));
    value += metallic_ * scale * f_ms_;
  }
  return value * mu_o;
}

float MetallicRoughnessBsdf::specular_probability(const BsdfContext& ctx, float mu_i) const {
  const bool specular = (ctx.lobes & specular_lobe()) != 0;
  const bool diffuse = (ctx.lobes & kLobeDiffuseReflection) != 0;
  if (!specular) return 0.f;
  if (!diffuse) return 1.f;
  // In proportion to the energy each part reflects from wi: the diffuse part's albedo is its
  // value integrated over mu_o, where the (1 - E(mu_o)) factor integrates to (1 - E_avg).
  const MicrofacetAlbedo a =
      smooth_ ? MicrofacetAlbedo{1.f, pow5(1.f - mu_i)} : ggx_albedo(mu_i, roughness_);
  const float ei = kDielectricF0 * (a.e - a.e5) + a.e5;
  const float d = mean((1.f - metallic_) * std::max(0.f, 1.f - ei) * base_color_ +
                       metallic_ * std::max(0.f, 1.f - a.e) * f_ms_);
  const float s = mean(specular_albedo(mu_i));
  if (!(d > 0.f)) return 1.f;
  if (!(s > 0.f)) return 0.f;
  return std::clamp(s / (s + d), 0.05f, 0.95f);
}

Spectrum MetallicRoughnessBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (wi.z <= 0.f || wo.z <= 0.f) return Spectrum(0.f);
  Spectrum value(0.f);
  if (ctx.lobes & kLobeDiffuseReflection) value += diffuse_value(wi.z, wo.z);
  if (!smooth_ && (ctx.lobes & kLobeGlossyReflection)) {
    const vec3 h = glm::normalize(wi + wo);
    // Walter et al. 2007 eq. 20 times cos theta_o: F D G / (4 cos_i).
    const float s = distr_.ndf(h) * distr_.smith_g(wi, wo, h) / (4.f * wi.z);
    if (std::isfinite(s)) value += fresnel(glm::dot(wi, h)) * s;
  }
  return value;
}

float MetallicRoughnessBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (wi.z <= 0.f || wo.z <= 0.f) return 0.f;
  const float p_spec = specular_probability(ctx, wi.z);
  float p = 0.f;
  if (ctx.lobes & kLobeDiffuseReflection) p += (1.f - p_spec) * cosine_hemisphere_pdf(wo);
  if (!smooth_ && (ctx.lobes & kLobeGlossyReflection)) {
    const vec3 h = glm::normalize(wi + wo);
    if (glm::dot(wo, h) > 0.f) {
      // Visible normals times the reflection Jacobian 1 / (4 wo.h) (see conductor.cpp).
      const float g = distr_.ndf(h) * distr_.smith_g1(wi, h) / (4.f * wi.z);
      if (std::isfinite(g)) p += p_spec * g;
    }
  }
  return p;
}

std::optional<BsdfSample> MetallicRoughnessBsdf::sample(const BsdfContext& ctx, const vec3& wi,
                                                        float u_lobe, const vec2& u) const {
  if (wi.z <= 0.f) return std::nullopt;
  const bool diffuse = (ctx.lobes & kLobeDiffuseReflection) != 0;
  const float p_spec = specular_probability(ctx, wi.z);
  if (!diffuse && p_spec <= 0.f) return std::nullopt;
  BsdfSample bs;
  bs.eta = 1.f;
  if (u_lobe < p_spec) {
    if (smooth_) {
      bs.wo = reflect_local(wi);
      bs.weight = fresnel(wi.z) / p_spec;
      bs.pdf = 0.f;
      bs.lobe = kLobeDeltaReflection;
      return bs;
    }
    const vec3 m = distr_.sample_visible(wi, u);
    bs.wo = reflect(wi, m);
    bs.lobe = kLobeGlossyReflection;
  } else {
    if (!diffuse) return std::nullopt;
    bs.wo = square_to_cosine_hemisphere(u);
    bs.lobe = kLobeDiffuseReflection;
  }
  if (bs.wo.z <= 0.f) return std::nullopt;
  // One-sample MIS over the lobes: the weight is f cos / (mixture pdf) (Veach 1997 ch. 9).
  bs.pdf = pdf(ctx, wi, bs.wo);
  if (!(bs.pdf > 0.f) || !std::isfinite(bs.pdf)) return std::nullopt;
  bs.weight = eval(ctx, wi, bs.wo) / bs.pdf;
  return bs;
}

}  // namespace penumbra
