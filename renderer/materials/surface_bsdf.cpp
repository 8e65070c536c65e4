#include "renderer/materials/surface_bsdf.h"

namespace penumbra {
namespace {

// Opaque models are two-sided: seen from the back (wi.z < 0) the surface behaves as its front
// with the frame mirrored through the tangent plane.
inline vec3 flip_z(const vec3& v) { return vec3(v.x, v.y, -v.z); }

inline float tan2_theta(const vec3& v) {
  const float c2 = v.z * v.z;
  return std::max(0.f, 1.f - c2) / c2;
}

// Estevez, Kulla, Cabrera and Lozano, "A Microfacet-Based Shadowing Function to Solve the Bump
// Terminator Problem" (Ray Tracing Gems, 2019), eq. 3-4, as Mitsuba 3's
// eval_shadow_terminator: G1 of a GGX surface whose alpha^2 = tan^2 of the perturbation / 8.
float shadow_terminator(const vec3& perturbed_n, const vec3& wo) {
  const float alpha2 = std::min(0.125f * tan2_theta(perturbed_n), 1.f);
  if (!(alpha2 > 0.f)) return 1.f;  // unperturbed: no shadowing (and no 0 * inf at grazing wo)
  return 2.f / (1.f + std::sqrt(1.f + alpha2 * tan2_theta(wo)));
}

// The model's answer to eval, pdf or both, as a BsdfEvalPdf.
template <bool kEval, bool kPdf, class Model>
[[gnu::always_inline]] inline BsdfEvalPdf model_evaluate(const Model& m, const BsdfContext& ctx,
                                                        const vec3& wi, const vec3& wo) {
  if constexpr (kEval && kPdf) {
    return m.eval_pdf(ctx, wi, wo);
  } else if constexpr (kEval) {
    return BsdfEvalPdf{m.eval(ctx, wi, wo), 0.f};
  } else {
    return BsdfEvalPdf{Spectrum(0.f), m.pdf(ctx, wi, wo)};
  }
}

}  // namespace

SurfaceBsdf::SurfaceBsdf(const BsdfModel& model)
    : model_(model), two_sided_(std::visit([](const auto& m) { return m.two_sided(); }, model)) {}

void SurfaceBsdf::set_mapped_normal(const vec3& n) {
  normal_mapped_ = true;
  mapped_normal_ = n;
}

Frame SurfaceBsdf::perturbed_frame(const vec3& wi) const {
  vec3 n = mapped_normal_;
  if (wi.z * glm::dot(wi, n) <= 0.f) n = vec3(-n.x, -n.y, n.z);
  const float len = glm::length(n);
  // A texel of (0.5, 0.5, 0.5) encodes no direction at all: keep the surface's normal.
  n = len > 1e-6f ? n / len : vec3(0.f, 0.f, 1.f);
  // Mitsuba's tangent: +x (dp/du) made orthogonal to n; any tangent where that degenerates.
  vec3 s = vec3(1.f, 0.f, 0.f) - n * n.x;
  const float ls = glm::length(s);
  if (!(ls > 1e-6f)) return Frame(n);
  Frame f;
  f.n = n;
  f.s = s / ls;
  f.t = glm::cross(n, f.s);
  return f;
}

template <bool kEval, bool kPdf>
BsdfEvalPdf SurfaceBsdf::evaluate_mapped(const BsdfContext& ctx, const vec3& wi,
                                         const vec3& wo) const {
  const Frame f = perturbed_frame(wi);
  const vec3 wo_p = f.to_local(wo), wi_p = f.to_local(wi);
  if (!(wo.z * wo_p.z > 0.f)) return BsdfEvalPdf{};
  BsdfEvalPdf r = std::visit(
      [&](const auto& m) { return model_evaluate<kEval, kPdf>(m, ctx, wi_p, wo_p); }, model_);
  if constexpr (kEval) r.f = r.f * shadow_terminator(f.n, wo);
  return r;
}

std::optional<BsdfSample> SurfaceBsdf::sample_mapped(const BsdfContext& ctx, const vec3& wi,
                                                     float u_lobe, const vec2& u) const {
  const Frame f = perturbed_frame(wi);
  std::optional<BsdfSample> bs =
      std::visit([&](const auto& m) { return m.sample(ctx, f.to_local(wi), u_lobe, u); }, model_);
  if (!bs) return std::nullopt;
  const vec3 wo = f.to_world(bs->wo);
  if (!(wo.z * bs->wo.z > 0.f)) return std::nullopt;
  bs->weight *= shadow_terminator(f.n, wo);
  bs->wo = wo;
  return bs;
}

template <bool kEval, bool kPdf>
BsdfEvalPdf SurfaceBsdf::evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  const bool flip = two_sided_ && wi.z < 0.f;
  const vec3 a = flip ? flip_z(wi) : wi, b = flip ? flip_z(wo) : wo;
  BsdfEvalPdf r =
      normal_mapped_
          ? evaluate_mapped<kEval, kPdf>(ctx, a, b)
          : std::visit([&](const auto& m) { return model_evaluate<kEval, kPdf>(m, ctx, a, b); },
                       model_);
  if constexpr (kEval) {
    if (!is_finite(r.f)) r.f = Spectrum(0.f);
  }
  if constexpr (kPdf) {
    if (!std::isfinite(r.pdf)) r.pdf = 0.f;
  }
  return r;
}

Spectrum SurfaceBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, false>(ctx, wi, wo).f;
}

float SurfaceBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<false, true>(ctx, wi, wo).pdf;
}

BsdfEvalPdf SurfaceBsdf::eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return evaluate<true, true>(ctx, wi, wo);
}

std::optional<BsdfSample> SurfaceBsdf::sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                              const vec2& u) const {
  const bool flip = two_sided_ && wi.z < 0.f;
  const vec3 a = flip ? flip_z(wi) : wi;
  std::optional<BsdfSample> bs =
      normal_mapped_ ? sample_mapped(ctx, a, u_lobe, u)
                     : std::visit([&](const auto& m) { return m.sample(ctx, a, u_lobe, u); }, model_);
  if (!bs) return std::nullopt;
  if (!is_finite(bs->weight) || !std::isfinite(bs->pdf) || !is_finite(bs->wo)) return std::nullopt;
  if (flip) bs->wo = flip_z(bs->wo);
  return bs;
}

Spectrum SurfaceBsdf::albedo() const {
  const Spectrum a = std::visit([](const auto& m) { return m.albedo(); }, model_);
  return glm::clamp(a, Spectrum(0.f), Spectrum(1.f));
}

Spectrum SurfaceBsdf::absorption() const {
  return std::visit([](const auto& m) { return m.absorption(); }, model_);
}

}  // namespace penumbra
