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

MicrofacetAlbedo MetallicRoughnessBsdf::lobe_albedo(float mu) const {
  return smooth_ ? MicrofacetAlbedo{1.f, pow5(1.f - mu)} : ggx_albedo(mu, roughness_);
}

Spectrum MetallicRoughnessBsdf::specular_albedo(const MicrofacetAlbedo& a) const {
  // Schlick is linear in f0: \int F s cos = f0 (E - E5) + E5.
  const float dielectric = kDielectricF0 * (a.e - a.e5) + a.e5;
  const Spectrum metal = base_color_ * (a.e - a.e5) + Spectrum(a.e5);
  return (1.f - metallic_) * Spectrum(dielectric) + metallic_ * metal;
}

Spectrum MetallicRoughnessBsdf::diffuse_value(const MicrofacetAlbedo& ai,
                                              const MicrofacetAlbedo& ao, float mu_o) const {
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

float MetallicRoughnessBsdf::specular_probability(const BsdfContext& ctx, float mu_i,
                                                  std::optional<MicrofacetAlbedo> ai) const {
  const bool specular = (ctx.lobes & specular_lobe()) != 0;
  const bool diffuse = (ctx.lobes & kLobeDiffuseReflection) != 0;
  if (!specular) return 0.f;
  if (!diffuse) return 1.f;
  // In proportion to the energy each part reflects from wi: the diffuse part's albedo is its
  // value integrated over mu_o, where the (1 - E(mu_o)) factor integrates to (1 - E_avg).
  const MicrofacetAlbedo a = ai ? *ai : lobe_albedo(mu_i);
  const float ei = kDielectricF0 * (a.e - a.e5) + a.e5;
  const float d = mean((1.f - metallic_) * std::max(0.f, 1.f - ei) * base_color_ +
                       metallic_ * std::max(0.f, 1.f - a.e) * f_ms_);
  const float s = mean(specular_albedo(a));
  if (!(d > 0.f)) return 1.f;
  if (!(s > 0.f)) return 0.f;
  return std::clamp(s / (s + d), 0.05f, 0.95f);
}

template <bool kEval, bool kPdf>
BsdfEvalPdf MetallicRoughnessBsdf::evaluate(const BsdfContext& ctx, const vec3& wi,
                                            const vec3& wo) const {
  BsdfEvalPdf r;
  if (wi.z <= 0.f || wo.z <= 0.f) return r;
  const bool diffuse = (ctx.lobes & kLobeDiffuseReflection) != 0;
  const bool glossy = !smooth_ && (ctx.lobes & kLobeGlossyReflection);
  // The lobe's albedo towards wi: a factor of the diffuse value, and what the lobe choice weighs
  // when both lobes are enabled.
  std::optional<MicrofacetAlbedo> ai;
  if (diffuse && (kEval || (ctx.lobes & specular_lobe()))) ai = lobe_albedo(wi.z);
  // The half vector, D and G1(wi), shared by value and density.
  vec3 h(0.f);
  float d = 0.f, g1_i = 0.f;
  if (glossy) {
    h = glm::normalize(wi + wo);
    if (kEval || glm::dot(wo, h) > 0.f) {
      d = distr_.ndf(h);
      g1_i = distr_.smith_g1(wi, h);
    }
  }
  if constexpr (kEval) {
    if (diffuse) r.f += diffuse_value(*ai, lobe_albedo(wo.z), wo.z);
    if (glossy) {
      // Walter et al. 2007 eq. 20 times cos theta_o: F D G / (4 cos_i), G = G1 G1.
      const float s = d * (g1_i * distr_.smith_g1(wo, h)) / (4.f * wi.z);
      if (std::isfinite(s)) r.f += fresnel(glm::dot(wi, h)) * s;
    }
  }
  if constexpr (kPdf) {
    const float p_spec = specular_probability(ctx, wi.z, ai);
    float p = 0.f;
    if (diffuse) p += (1.f - p_spec) * cosine_hemisphere_pdf(wo);
    if (glossy && glm::dot(wo, h) > 0.f) {
      // Visible normals times the reflection Jacobian 1 / (4 wo.h) (see conductor.cpp).
      const float g = d * g1_i / (4.f * wi.z);
      if (std::isfinite(g)) p += p_spec * g;
    }
    r.pdf = p;
  }
  return r;
}

Spectrum MetallicRoughnessBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, false>(ctx, wi, wo).f;
}

float MetallicRoughnessBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<false, true>(ctx, wi, wo).pdf;
}

BsdfEvalPdf MetallicRoughnessBsdf::eval_pdf(const BsdfContext& ctx, const vec3& wi,
                                            const vec3& wo) const {
  return evaluate<true, true>(ctx, wi, wo);
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
  const BsdfEvalPdf ep = eval_pdf(ctx, wi, bs.wo);
  bs.pdf = ep.pdf;
  if (!(bs.pdf > 0.f) || !std::isfinite(bs.pdf)) return std::nullopt;
  bs.weight = ep.f / bs.pdf;
  return bs;
}

}  // namespace penumbra
