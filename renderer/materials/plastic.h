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
#include <array>

#include "renderer/materials/bsdf.h"
#include "renderer/materials/coating_tables.h"
#include "renderer/materials/material_params.h"
#include "renderer/materials/microfacet.h"

namespace penumbra {

// Front-side model (wi.z > 0); Material mirrors back-side queries to the front.
class PlasticBsdf : public OpaqueBsdf {
 public:
  // `cache` shares the coating's tables between the materials of one scene build; without one
  // they are computed for this material alone.
  explicit PlasticBsdf(const PlasticParams& params, CoatingTableCache* cache = nullptr);

  bool smooth() const { return smooth_; }
  uint32_t lobes() const {
    return kLobeDiffuseReflection | (smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection);
  }
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

  // Exposed for tests: the coating's internal diffuse reflectance and external transmittance.
  float internal_reflectance() const { return internal_reflectance_; }
  float external_transmittance(float cos_theta) const;

 private:
  // Probability of sampling the coating lobe given the enabled lobes.
  float specular_probability(const BsdfContext& ctx, float cos_i) const;
  uint32_t coating_lobe() const { return smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection; }

  Spectrum color_;
  float eta_;
  bool smooth_;
  GgxDistribution distr_;
  float specular_sampling_weight_;
  float internal_reflectance_;  // fdr_int (smooth) or its rough counterpart
  float diffuse_scale_;         // 1 / (eta^2 (1 - internal_reflectance_)), computed in double
  int nodes_ = 0;                                       // used entries of the rough table
  std::array<float, kCoatingTableCapacity> cosines_{};  // the rough table's nodes, increasing
  std::array<float, kCoatingTableCapacity> transmittance_{};
};

}  // namespace penumbra
