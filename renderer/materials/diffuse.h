#pragma once
// Lambertian reflection.
//
// Defined here, not in a .cpp: SurfaceBsdf dispatches over its models with std::visit, which
// libstdc++ compiles to a switch, and with the bodies visible the most common model inlines into
// that switch instead of being a call that returns its std::optional through memory
// (docs/performance.md).
#include <optional>

#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

// Front-side model (wi.z > 0); Material mirrors back-side queries to the front.
class DiffuseBsdf : public OpaqueBsdf {
 public:
  explicit DiffuseBsdf(const Spectrum& color) : color_(color) {}
  explicit DiffuseBsdf(const DiffuseParams& params) : DiffuseBsdf(params.color) {}

  uint32_t lobes() const { return kLobeDiffuseReflection; }
  // The first-hit albedo of the "albedo" output (docs/output-layers.md): the reflectance.
  Spectrum albedo() const { return color_; }

  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
    return evaluate<true, false>(ctx, wi, wo).f;
  }
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
    return evaluate<false, true>(ctx, wi, wo).pdf;
  }
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
    return evaluate<true, true>(ctx, wi, wo);
  }

  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float,
                                   const vec2& u) const {
    if (!(ctx.lobes & kLobeDiffuseReflection) || wi.z <= 0.f) return std::nullopt;
    BsdfSample bs;
    bs.wo = square_to_cosine_hemisphere(u);
    bs.pdf = cosine_hemisphere_pdf(bs.wo);
    if (!(bs.pdf > 0.f)) return std::nullopt;
    // f cos / pdf = (color / pi) cos / (cos / pi).
    bs.weight = color_;
    bs.lobe = kLobeDiffuseReflection;
    bs.eta = 1.f;
    return bs;
  }

 private:
  // The one body of eval (kEval), pdf (kPdf) and eval_pdf (both).
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
    BsdfEvalPdf r;
    if (!(ctx.lobes & kLobeDiffuseReflection) || wi.z <= 0.f || wo.z <= 0.f) return r;
    if constexpr (kEval) r.f = color_ * (kInvPi * wo.z);
    if constexpr (kPdf) r.pdf = cosine_hemisphere_pdf(wo);
    return r;
  }

  Spectrum color_;
};

}  // namespace penumbra
