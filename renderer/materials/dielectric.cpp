#include "renderer/materials/dielectric.h"

#include "renderer/materials/fresnel.h"

namespace penumbra {

namespace {
// ior this close to 1 is treated as an invisible interface: below it the refraction Jacobian
// (wi.m + eta wo.m)^-2 loses all precision in float.
constexpr float kIndexMatchedTolerance = 1e-4f;
}  // namespace

DielectricBsdf::DielectricBsdf(float ior, float roughness, const Spectrum& absorption)
    : eta_(ior),
      absorption_(absorption),
      index_matched_(std::abs(ior - 1.f) < kIndexMatchedTolerance),
      smooth_(roughness_to_alpha(roughness) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(roughness)) {}

uint32_t DielectricBsdf::lobes() const {
  if (index_matched_) return kLobeDeltaTransmission;
  if (smooth_) return kLobeDeltaReflection | kLobeDeltaTransmission;
  return kLobeGlossyReflection | kLobeGlossyTransmission;
}

bool DielectricBsdf::half_vector(const vec3& wi, const vec3& wo, vec3& m, float& eta,
                                 bool& is_reflection) const {
  is_reflection = wi.z * wo.z > 0.f;
  eta = wi.z > 0.f ? eta_ : 1.f / eta_;
  // Reflection: h = wi + wo (eq. 13). Refraction: h = -(eta_i wi + eta_o wo) (eq. 16), i.e.
  // proportional to wi + eta wo; either way orient it towards +z.
  vec3 h = is_reflection ? wi + wo : wi + eta * wo;
  const float len = glm::length(h);
  if (!(len > 0.f)) return false;
  h /= len;
  if (h.z < 0.f) h = -h;
  m = h;
  // The micro- and macro-surface must agree on the side of both directions (the condition the
  // Smith G1 terms encode; repeating it here keeps pdf() consistent with sample()).
  return glm::dot(wi, m) * wi.z > 0.f && glm::dot(wo, m) * wo.z > 0.f;
}

template <bool kEval, bool kPdf>
BsdfEvalPdf DielectricBsdf::evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  BsdfEvalPdf r;
  if (index_matched_ || smooth_ || wi.z == 0.f || wo.z == 0.f) return r;
  vec3 m;
  float eta;
  bool is_reflection;
  if (!half_vector(wi, wo, m, eta, is_reflection)) return r;
  const bool has_r = ctx.lobes & kLobeGlossyReflection;
  const bool has_t = ctx.lobes & kLobeGlossyTransmission;
  if (is_reflection ? !has_r : !has_t) return r;

  // Shared by value and density: D(m), G1(wi, m) (the visible-normal density's G1 of the front
  // copy of wi is the same number: G1 depends on v only through v.z^2, v.x^2 + v.y^2 and the sign
  // of (v.m) v.z, none of which negating v changes), the Fresnel term and the dot products.
  const float d = distr_.ndf(m);
  const float g1_i = distr_.smith_g1(wi, m);
  const float dot_i = glm::dot(wi, m), dot_o = glm::dot(wo, m);
  // The value needs F always, the density only to choose between two enabled lobes.
  float f = 0.f;
  if (kEval || (has_r && has_t)) f = fresnel_dielectric(dot_i, eta_).reflectance;
  const float denom = dot_i + eta * dot_o;  // refraction only

  if constexpr (kEval) {
    const float g = g1_i * distr_.smith_g1(wo, m);
    float value;
    if (is_reflection) {
      // Walter et al. 2007 eq. 20 times |cos_o|.
      value = f * d * g / (4.f * std::abs(wi.z));
    } else {
      // Walter et al. 2007 eq. 21 times |cos_o|:
      //   |wi.m||wo.m| eta^2 (1 - F) D G / (|cos_i| (wi.m + eta wo.m)^2),
      // and the radiance scaling 1/eta^2 cancels the eta^2.
      value = std::abs((1.f - f) * d * g * dot_i * dot_o / (wi.z * denom * denom));
    }
    if (std::isfinite(value)) r.f = Spectrum(value);
  }
  if constexpr (kPdf) {
    // Jacobians dm/dwo: reflection 1 / (4 |wo.m|) (eq. 14), refraction
    // eta^2 |wo.m| / (wi.m + eta wo.m)^2 (eq. 17).
    const float jacobian = is_reflection ? 1.f / (4.f * std::abs(dot_o))
                                         : eta * eta * std::abs(dot_o) / (denom * denom);
    // The visible-normal density of the side wi is on (GgxDistribution::pdf_visible).
    const vec3 wi_front = wi.z > 0.f ? wi : -wi;
    const float p_m = GgxDistribution::visible_density(d, g1_i, wi_front, m);
    float p = p_m * jacobian;
    if (has_r && has_t) p *= is_reflection ? f : 1.f - f;
    if (std::isfinite(p)) r.pdf = p;
  }
  return r;
}

Spectrum DielectricBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, false>(ctx, wi, wo).f;
}

float DielectricBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<false, true>(ctx, wi, wo).pdf;
}

BsdfEvalPdf DielectricBsdf::eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, true>(ctx, wi, wo);
}

std::optional<BsdfSample> DielectricBsdf::sample(const BsdfContext& ctx, const vec3& wi,
                                                 float u_lobe, const vec2& u) const {
  if (wi.z == 0.f) return std::nullopt;
  if (index_matched_) {
    if (!(ctx.lobes & kLobeDeltaTransmission)) return std::nullopt;
    BsdfSample bs;
    bs.wo = -wi;
    bs.weight = Spectrum(1.f);
    bs.pdf = 0.f;
    bs.lobe = kLobeDeltaTransmission;
    bs.eta = 1.f;
    return bs;
  }
  return smooth_ ? sample_smooth(ctx, wi, u_lobe) : sample_rough(ctx, wi, u_lobe, u);
}

std::optional<BsdfSample> DielectricBsdf::sample_smooth(const BsdfContext& ctx, const vec3& wi,
                                                        float u_lobe) const {
  const bool has_r = ctx.lobes & kLobeDeltaReflection;
  const bool has_t = ctx.lobes & kLobeDeltaTransmission;
  if (!has_r && !has_t) return std::nullopt;
  const FresnelDielectric fr = fresnel_dielectric(wi.z, eta_);
  const float r = fr.reflectance, t = 1.f - r;

  bool pick_r;
  float weight;
  if (has_r && has_t) {
    // Choose the lobe with its Fresnel probability: the weight is then 1 (times 1/eta^2).
    pick_r = u_lobe < r;
    weight = 1.f;
  } else {
    pick_r = has_r;
    weight = has_r ? r : t;
  }
  if (!(weight > 0.f)) return std::nullopt;

  BsdfSample bs;
  bs.pdf = 0.f;
  if (pick_r) {
    bs.wo = reflect_local(wi);
    bs.lobe = kLobeDeltaReflection;
    bs.eta = 1.f;
  } else {
    bs.wo = refract_local(wi, fr.cos_t, fr.eta_ti);
    bs.lobe = kLobeDeltaTransmission;
    bs.eta = fr.eta_it;
    // Radiance is compressed into the smaller solid angle: L_t = (eta_i/eta_t)^2 T L_i.
    weight *= fr.eta_ti * fr.eta_ti;
  }
  bs.weight = Spectrum(weight);
  return bs;
}

std::optional<BsdfSample> DielectricBsdf::sample_rough(const BsdfContext& ctx, const vec3& wi,
                                                       float u_lobe, const vec2& u) const {
  const bool has_r = ctx.lobes & kLobeGlossyReflection;
  const bool has_t = ctx.lobes & kLobeGlossyTransmission;
  if (!has_r && !has_t) return std::nullopt;

  // Sample a visible normal from the side wi is on; m is always in the +z hemisphere.
  const vec3 wi_front = wi.z > 0.f ? wi : -wi;
  const vec3 m = distr_.sample_visible(wi_front, u);
  const float pdf_m = distr_.pdf_visible(wi_front, m);
  if (!(pdf_m > 0.f)) return std::nullopt;

  const float dot_i = glm::dot(wi, m);
  const FresnelDielectric fr = fresnel_dielectric(dot_i, eta_);
  const float f = fr.reflectance;

  bool pick_r;
  float weight, pdf = pdf_m;
  if (has_r && has_t) {
    pick_r = u_lobe < f;
    weight = 1.f;
    pdf *= pick_r ? f : 1.f - f;
  } else {
    pick_r = has_r;
    weight = has_r ? f : 1.f - f;
  }
  if (!(weight > 0.f) || !(pdf > 0.f)) return std::nullopt;

  BsdfSample bs;
  float jacobian;
  if (pick_r) {
    bs.wo = reflect(wi, m);
    if (bs.wo.z * wi.z <= 0.f) return std::nullopt;
    bs.lobe = kLobeGlossyReflection;
    bs.eta = 1.f;
    jacobian = 1.f / (4.f * std::abs(glm::dot(bs.wo, m)));  // Walter et al. 2007 eq. 14
  } else {
    bs.wo = refract(wi, m, fr.cos_t, fr.eta_ti);
    if (bs.wo.z * wi.z >= 0.f) return std::nullopt;
    bs.lobe = kLobeGlossyTransmission;
    bs.eta = fr.eta_it;
    const float dot_o = glm::dot(bs.wo, m);
    const float denom = dot_i + fr.eta_it * dot_o;
    jacobian = fr.eta_it * fr.eta_it * std::abs(dot_o) / (denom * denom);  // eq. 17
    weight *= fr.eta_ti * fr.eta_ti;  // radiance scaling 1/eta^2
  }
  // With visible-normal sampling f |cos_o| / pdf reduces to G1(wo, m) (Heitz 2014 eq. 19).
  const float g1 = distr_.smith_g1(bs.wo, m);
  weight *= g1;
  bs.pdf = pdf * jacobian;
  if (!(weight > 0.f) || !(bs.pdf > 0.f) || !std::isfinite(bs.pdf) || !std::isfinite(weight))
    return std::nullopt;
  bs.weight = Spectrum(weight);
  return bs;
}

}  // namespace penumbra
