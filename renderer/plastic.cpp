#include "renderer/plastic.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include "renderer/fresnel.h"
#include "renderer/sampling.h"

namespace penumbra {
namespace {

// What a coating needs that depends only on (alpha, eta): the rough coating's transmittance
// table, the internal diffuse reflectance fdr_int and the diffuse factor 1 / (eta^2 (1 - fdr_int)).
struct CoatingTables {
  // Rough coating only: t at the increasing cosines (nodes[0] = 0, nodes[n - 1] = 1).
  std::array<float, PlasticBsdf::kTransmittanceRes> cosines{};
  std::array<float, PlasticBsdf::kTransmittanceRes> transmittance{};
  float internal_reflectance = 0.f;
  float diffuse_scale = 0.f;
};

// 1 / (eta^2 (1 - fdr_int)) in double: near 1 (large ior) fdr_int in float would lose the
// difference, and eta^2 overflows a float for the largest valid ior. 0 if nothing gets out.
float diffuse_scale(double eta, double internal_transmittance) {
  const double d = eta * eta * internal_transmittance;
  return d > 0.0 ? float(1.0 / d) : 0.f;
}

CoatingTables smooth_coating_tables(float eta) {
  // Light inside the coating sees the relative ior 1/eta. The exact average makes
  // eta^2 (1 - fdr_int) equal the external diffuse transmittance 1 - fdr_ext (see
  // fresnel_diffuse), so the smooth plastic with a white base reflects exactly 1 at every angle.
  // (With Mitsuba's polynomial fit a white plastic rendered 1.016 in a furnace at ior 2.4, and
  // at ior 4 the fit's fdr_int exceeds 1.)
  const DiffuseFresnel internal = fresnel_diffuse(1.0 / double(eta));
  CoatingTables tables;
  tables.internal_reflectance = float(internal.reflectance);
  tables.diffuse_scale = diffuse_scale(eta, internal.transmittance);
  return tables;
}

// Cosines at which the rough coating's external transmittance t(mu) is tabulated. Where t varies
// fastest, linear interpolation between uniform nodes over-estimates it, and the interpolated t
// added to the exactly evaluated glossy reflection then exceeds 1 (measured with Mitsuba's
// uniform nodes: 1.004 at 89.9 degrees for ior 1.01, roughness 0.0101; 1.32 at the critical
// angle for ior 0.5). So the nodes cluster where t has its steep foot:
// - eta >= 1: at grazing incidence, mu = x^2 for x uniform in [0, 1] (measured: <= 1 for ior
//   1.0001..1e30, roughness 0.0101..1, 0..89.999 degrees);
// - eta < 1 (the coating is the thinner medium): onto the critical cosine mu_c = sqrt(1 - eta^2),
//   below which a smooth coating reflects totally (t = 0) and above which t grows like
//   sqrt(mu - mu_c): half the nodes below (cubic clustering: the rough foot of t is narrow),
//   half above (quadratic, which makes the sqrt onset linear). This leaves a gain near the
//   critical angle at roughness 0.05..0.1 of up to 2% at ior 0.1, 0.7% at ior 0.3 and 0.3% at
//   ior 0.5..0.9, left open (likely also because the table values are Gauss-Legendre integrals
//   across the total-reflection discontinuity).
std::array<float, PlasticBsdf::kTransmittanceRes> transmittance_nodes(float eta) {
  constexpr int n = PlasticBsdf::kTransmittanceRes;
  std::array<float, n> nodes{};
  if (eta >= 1.f) {
    for (int i = 0; i < n; ++i) {
      const double x = double(i) / (n - 1);
      nodes[i] = float(x * x);
    }
  } else {
    const double mu_c = std::sqrt(1.0 - double(eta) * eta);
    constexpr int below = n / 2;  // nodes[0 .. below] span [0, mu_c]
    for (int i = 0; i <= below; ++i) {
      const double w = 1.0 - double(i) / below;
      nodes[i] = float(mu_c * (1.0 - w * w * w));
    }
    for (int i = below + 1; i < n; ++i) {
      const double v = double(i - below) / (n - 1 - below);
      nodes[i] = float(mu_c + (1.0 - mu_c) * v * v);
    }
  }
  nodes[n - 1] = 1.f;
  return nodes;
}

CoatingTables rough_coating_tables(const GgxDistribution& distr, float eta) {
  // Tabulate the external transmittance t(mu) (at the nodes above, clamped away from 0) and
  // average the internal reflectance 2 \int R_int(mu) mu dmu as the mean over mu =
  // linspace(0, 1) -- Mitsuba 3's roughplastic takes the same mean (and tabulates t on the same
  // uniform nodes), so the diffuse part matches it. That mean underestimates the average by about
  // (fdr_int - R_int(1)) / 64, so the rough plastic returns less light than the smooth one
  // (furnace at roughness 0.0101: 0.986 at ior 1.5, 0.83 at ior 10), not more.
  constexpr int n = PlasticBsdf::kTransmittanceRes;
  CoatingTables tables;
  tables.cosines = transmittance_nodes(eta);
  std::array<double, n> internal{};
  tbb::parallel_for(0, n, [&](int i) {
    tables.transmittance[i] =
        rough_dielectric_transmittance(distr, std::max(1e-6f, tables.cosines[i]), eta);
    const float mu = std::max(1e-6f, float(i) / float(n - 1));
    internal[i] = rough_dielectric_reflectance(distr, mu, 1.f / eta) * mu;
  });
  double sum = 0.0;
  for (double v : internal) sum += v;  // fixed order: the result does not depend on threads
  const double reflectance = 2.0 * sum / n;
  tables.internal_reflectance = float(reflectance);
  tables.diffuse_scale = diffuse_scale(eta, 1.0 - reflectance);
  return tables;
}

// The rough tables cost ~10^6 microfacet evaluations, the smooth ones a few hundred Fresnel
// evaluations; they depend only on (alpha, eta) (alpha 0 for smooth), so every material (and
// every scene a long-running server builds) with the same coating shares them.
const CoatingTables& coating_tables(bool smooth, const GgxDistribution& distr, float eta) {
  static std::mutex mutex;
  static std::map<std::pair<float, float>, std::unique_ptr<CoatingTables>> cache;
  const std::pair<float, float> key(smooth ? 0.f : distr.alpha(), eta);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = cache.find(key); it != cache.end()) return *it->second;
  }
  // Built outside the lock: two threads may both build the same entry; the first one stays.
  auto tables = std::make_unique<CoatingTables>(smooth ? smooth_coating_tables(eta)
                                                       : rough_coating_tables(distr, eta));
  std::lock_guard<std::mutex> lock(mutex);
  auto [it, inserted] = cache.emplace(key, std::move(tables));
  return *it->second;
}

}  // namespace

PlasticBsdf::PlasticBsdf(const PlasticParams& params)
    : color_(params.color),
      eta_(params.ior),
      smooth_(roughness_to_alpha(params.roughness) < kMinMicrofacetAlpha),
      distr_(roughness_to_alpha(params.roughness)) {
  // Steer samples between coating and base by their mean reflectances (coating reflectance 1),
  // as Mitsuba does, so the integrator sees the same sampling weights. Only the variance depends
  // on them: every sample is weighted by eval / pdf (or F / P(coating) for the Dirac lobe).
  const float d_mean = (color_.x + color_.y + color_.z) / 3.f;
  specular_sampling_weight_ = 1.f / (d_mean + 1.f);

  const CoatingTables& tables = coating_tables(smooth_, distr_, eta_);
  cosines_ = tables.cosines;
  transmittance_ = tables.transmittance;
  internal_reflectance_ = tables.internal_reflectance;
  diffuse_scale_ = tables.diffuse_scale;
}

float PlasticBsdf::external_transmittance(float cos_theta) const {
  if (smooth_) return 1.f - fresnel_dielectric(cos_theta, eta_).reflectance;
  // Linear interpolation between the table's nodes.
  const float mu = std::clamp(cos_theta, 0.f, 1.f);
  const auto upper = std::upper_bound(cosines_.begin() + 1, cosines_.end() - 1, mu);
  const int i = int(upper - cosines_.begin()) - 1;
  // Nodes coincide where the critical cosine rounds to 1 (ior < ~3e-4).
  const float width = cosines_[i + 1] - cosines_[i];
  const float w = width > 0.f ? (mu - cosines_[i]) / width : 1.f;
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
