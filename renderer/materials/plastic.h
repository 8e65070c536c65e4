#pragma once
// Diffuse base under a dielectric coating: Mitsuba 3's `plastic` (smooth coating) and
// `roughplastic` (GGX coating, visible-normal sampling) with nonlinear = false.
//
// Model (Weidlich & Wilkie 2007, "Arbitrarily Layered Micro-Facet Surfaces", as simplified in
// Mitsuba): light refracts into the coating, scatters diffusely off the base with albedo `color`,
// bounces between base and coating (geometric series with the coating's internal diffuse
// reflectance fdr_int, the linear form 1 / (1 - fdr_int)), and refracts out; the 1/eta^2 factor
// accounts for the radiance change across the coating. Smooth coating: transmittances
// (1 - F(cos_i)) (1 - F(cos_o)) and fdr_int by exact quadrature (Mitsuba uses a polynomial fit,
// which gains energy at high ior); rough coating: the precomputed rough-dielectric transmittance
// table t(cos) and internal reflectance.
#include "renderer/materials/bsdf.h"
#include "renderer/materials/coating_tables.h"
#include "renderer/materials/material_params.h"
#include "renderer/materials/microfacet.h"

namespace penumbra {

// Front-side model (wi.z > 0); Material mirrors back-side queries to the front.
class PlasticBsdf : public OpaqueBsdf {
 public:
  // `tables` are the coating's (tables_for), owned elsewhere (by the scene's CoatingTableCache)
  // and held by pointer, so a per-hit copy of the model (a textured colour) copies no table.
  PlasticBsdf(const PlasticParams& params, const CoatingTables& tables);
  // The coating's tables for these parameters, from (and owned by) `cache`.
  static const CoatingTables& tables_for(const PlasticParams& params, CoatingTableCache& cache);

  // The same coating over a base of another colour (a textured base, per hit).
  PlasticBsdf with_color(const Spectrum& color) const;

  bool smooth() const { return smooth_; }
  uint32_t lobes() const {
    return kLobeDiffuseReflection | (smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection);
  }
  // The base's diffuse reflectance (the colour a denoiser should keep; the clear coat adds
  // about 4% white), as Cycles' denoising albedo of a dielectric principled BSDF.
  Spectrum albedo() const { return color_; }
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

  // The constants the wavefront driver's surface stage reads (render/lane_bsdfs.h repeats this
  // model's arithmetic on them).
  float eta() const { return eta_; }
  float alpha() const { return distr_.alpha(); }
  float specular_sampling_weight() const { return specular_sampling_weight_; }
  float diffuse_scale() const { return diffuse_scale_; }
  const CoatingTables& tables() const { return *tables_; }
  // Exposed for tests: the coating's internal diffuse reflectance and external transmittance.
  float internal_reflectance() const { return internal_reflectance_; }
  float external_transmittance(float cos_theta) const;

 private:
  // The one body of eval (kEval), pdf (kPdf) and eval_pdf (both).
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // Probability of sampling the coating lobe given the enabled lobes; `t_i`, if the caller has
  // it, is external_transmittance(cos_i).
  float specular_probability(const BsdfContext& ctx, float cos_i,
                             std::optional<float> t_i = std::nullopt) const;
  uint32_t coating_lobe() const { return smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection; }

  void set_color(const Spectrum& color);

  Spectrum color_;
  float eta_;
  bool smooth_;
  GgxDistribution distr_;
  float specular_sampling_weight_;
  const CoatingTables* tables_;  // the rough transmittance table t(cos) lives here
  float internal_reflectance_;  // fdr_int (smooth) or its rough counterpart
  float diffuse_scale_;         // 1 / (eta^2 (1 - internal_reflectance_)), computed in double
};

}  // namespace penumbra
