#include "renderer/plastic.h"

#include <tbb/parallel_for.h>

#include <map>
#include <mutex>

#include "renderer/fresnel.h"
#include "renderer/sampling.h"

namespace penumbra {
namespace {

struct RoughCoatingTables {
  std::array<float, PlasticBsdf::kTransmittanceRes> transmittance;
  float internal_reflectance;
};

// The tables cost ~10^6 microfacet evaluations; they depend only on (alpha, eta), so every
// material (and every scene a long-running server builds) with the same coating shares them.
const RoughCoatingTables& rough_coating_tables(const GgxDistribution& distr, float eta) {
  static std::mutex mutex;
  static std::map<std::pair<float, float>, std::unique_ptr<RoughCoatingTables>> cache;
  const std::pair<float, float> key(distr.alpha(), eta);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = cache.find(key); it != cache.end()) return *it->second;
  }
  auto tables = std::make_unique<RoughCoatingTables>();
  std::array<double, PlasticBsdf::kTransmittanceRes> internal{};
  tbb::parallel_for(0, PlasticBsdf::kTransmittanceRes, [&](int i) {
    const float mu = std::max(1e-6f, float(i) / float(PlasticBsdf::kTransmittanceRes - 1));
    tables->transmittance[i] = rough_dielectric_transmittance(distr, mu, eta);
    internal[i] = rough_dielectric_reflectance(distr, mu, 1.f / eta) * mu;
  });
  double sum = 0.0;
  for (double v : internal) sum += v;  // fixed order: the result does not depend on threads
  tables->internal_reflectance = float(2.0 * sum / PlasticBsdf::kTransmittanceRes);
  std::lock_guard<std::mutex> lock(mutex);
  auto [it, inserted] = cache.emplace(key, std::move(tables));
  return *it->second;
}

}  // namespace

PlasticBsdf::PlasticBsdf(const PlasticParams& params)
    : color_(params.color),
      eta_(params.ior),
      inv_eta2_(1.f / (params.ior * params.ior)),
      smooth_(roughness_to_alpha(params.roughness) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(params.roughness)) {
  // Steer samples between coating and base by their mean reflectances (coating reflectance 1),
  // as Mitsuba does, so the integrator sees the same sampling weights.
  const float d_mean = (color_.x + color_.y + color_.z) / 3.f;
  specular_sampling_weight_ = 1.f / (d_mean + 1.f);

  if (smooth_) {
    // Light inside the coating sees the relative ior 1/eta.
    internal_reflectance_ = fresnel_diffuse_reflectance(1.f / eta_);
    return;
  }
  // Rough coating: tabulate the external transmittance t(mu) on mu = linspace(0, 1) (clamped
  // away from 0) and average the internal reflectance 2 \int R_int(mu) mu dmu over the same
  // nodes -- the tables Mitsuba 3's roughplastic builds, so the diffuse part matches it.
  const RoughCoatingTables& tables = rough_coating_tables(distr_, eta_);
  transmittance_ = tables.transmittance;
  internal_reflectance_ = tables.internal_reflectance;
}

float PlasticBsdf::external_transmittance(float cos_theta) const {
  if (smooth_) return 1.f - fresnel_dielectric(cos_theta, eta_).reflectance;
  // Linear interpolation in the table.
  const float x = std::clamp(cos_theta, 0.f, 1.f) * float(kTransmittanceRes - 1);
  const int i = std::min(int(x), kTransmittanceRes - 2);
  const float w = x - float(i);
  return (1.f - w) * transmittance_[i] + w * transmittance_[i + 1];
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
    value += color_ * (t * inv_eta2_ * kInvPi * wo.z / (1.f - internal_reflectance_));
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
