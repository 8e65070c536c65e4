#pragma once
// Dielectric interface between the exterior (ior 1, the +z side) and the interior (ior `ior`).
// Smooth: Fresnel-weighted choice between Dirac reflection and refraction, with total internal
// reflection. Rough: Walter et al. 2007, "Microfacet Models for Refraction through Rough
// Surfaces", with GGX and visible-normal sampling (the model of Mitsuba 3's `roughdielectric`).
// Radiance transport: refracted radiance is scaled by 1/eta^2 (Veach 1997, sec. 5.2).
#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"
#include "renderer/materials/microfacet.h"

namespace penumbra {

class DielectricBsdf {
 public:
  DielectricBsdf(float ior, float roughness, const Spectrum& absorption);
  explicit DielectricBsdf(const DielectricParams& params)
      : DielectricBsdf(params.ior, params.roughness, params.absorption) {}

  // Index-matched (ior == 1): the interface is invisible, a Dirac transmission of weight 1.
  bool index_matched() const { return index_matched_; }
  bool smooth() const { return smooth_; }
  float ior() const { return eta_; }
  float alpha() const { return distr_.alpha(); }  // GGX alpha, clamped as the lobes use it
  // Oriented: +z is the outside, so the back is the inside, not a mirrored front.
  static constexpr bool two_sided() { return false; }
  // Beer-Lambert sigma_a of the interior; the integrator applies it along segments inside.
  Spectrum absorption() const { return absorption_; }
  uint32_t lobes() const;
  // 1: OIDN's documented albedo for dielectrics (docs/output-layers.md); the transmitted
  // colour is the absorption's, which depends on the path length, not the surface.
  Spectrum albedo() const { return Spectrum(1.f); }
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

 private:
  // The one body of eval (kEval), pdf (kPdf) and eval_pdf (both).
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample_smooth(const BsdfContext& ctx, const vec3& wi,
                                          float u_lobe) const;
  std::optional<BsdfSample> sample_rough(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                         const vec2& u) const;
  // Generalised half vector (Walter et al. 2007 eq. 13 and 16) oriented to +z, plus the relative
  // ior eta = eta_o / eta_i; returns false when wi, wo and m do not form a valid configuration.
  bool half_vector(const vec3& wi, const vec3& wo, vec3& m, float& eta, bool& is_reflection) const;

  float eta_;  // interior / exterior
  Spectrum absorption_;
  bool index_matched_;
  bool smooth_;
  GgxDistribution distr_;
};

}  // namespace penumbra
