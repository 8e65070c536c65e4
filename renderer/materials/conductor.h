#pragma once
// Conductor with a constant (angle-independent) Fresnel reflectance: a perfect mirror when smooth,
// GGX microfacet reflection when rough (the model of Mitsuba 3's `conductor` / `roughconductor`
// with distribution = ggx, sample_visible = true and specular_reflectance = color).
#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"
#include "renderer/materials/microfacet.h"

namespace penumbra {

// Front-side model (wi.z > 0); Material mirrors back-side queries to the front.
class ConductorBsdf : public OpaqueBsdf {
 public:
  ConductorBsdf(const Spectrum& color, float roughness);
  explicit ConductorBsdf(const ConductorParams& params) : ConductorBsdf(params.color, params.roughness) {}

  bool smooth() const { return smooth_; }
  float alpha() const { return distr_.alpha(); }  // GGX alpha, clamped as the lobe uses it
  uint32_t lobes() const { return smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection; }
  // Reflectance at normal incidence, OIDN's albedo for metals (docs/output-layers.md); the
  // model's Fresnel term is constant, so it is `color` at every angle.
  Spectrum albedo() const { return color_; }
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

 private:
  // The one body of eval (kEval), pdf (kPdf) and eval_pdf (both).
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;

  Spectrum color_;
  bool smooth_;
  GgxDistribution distr_;
};

}  // namespace penumbra
