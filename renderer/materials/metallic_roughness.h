#pragma once
// glTF 2.0's metallic-roughness material as an energy-conserving BSDF (docs/gltf.md, "The
// material").
//
// The structure is the glTF specification's (Appendix B, "BRDF implementation"):
//   material = mix(dielectric, metal, metallic)
//   metal    = Schlick Fresnel with f0 = base colour  x  GGX specular (alpha = roughness^2)
//   dielectric = GGX specular with Schlick Fresnel f0 = 0.04 (ior 1.5) layered over a
//                Lambertian base of the base colour
// with two changes that make it conserve energy, both from Kulla and Conty 2017 ("Revisiting
// Physically Based Shading at Imageworks", SIGGRAPH course), the technique glTF's own
// KHR_materials_sheen and KHR_materials_clearcoat extensions name "albedo scaling":
//  * the dielectric's diffuse base receives what the specular layer does not reflect, in both
//    directions and reciprocally:
//      f_base = base / pi * (1 - E_F(mu_i)) (1 - E_F(mu_o)) / (1 - E_F,avg)
//    (E_F: the directional albedo of the Fresnel-weighted specular layer), instead of the
//    appendix's base * (1 - F(v.h)) / pi, which gains or loses energy depending on roughness;
//  * the metal adds the multiple scattering single-scattering GGX loses:
//      f_ms = F_ms (1 - E(mu_i)) (1 - E(mu_o)) / (pi (1 - E_avg)),
//      F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),  F_avg = f0 + (1 - f0) / 21.
// A white surface (base colour 1) then reflects all energy for every roughness, metallic and
// angle (the white furnace, up to the albedo table's interpolation), and any base colour <= 1
// reflects at most all of it. The E tables are microfacet_albedo.h's.
//
// Roughness below 0.01 (alpha < 1e-4, as the other models) makes the specular lobe a Dirac
// mirror with the same Fresnel weights.
//
// The wavefront driver's surface stage repeats the rough model operation for operation
// (render/lane_bsdfs.h, lane::MetallicRoughness): a change here must be made there too, which
// tests/renderer/render/surface_stage_test.cpp catches.
#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"
#include "renderer/materials/microfacet.h"
#include "renderer/materials/microfacet_albedo.h"

namespace penumbra {

// Front-side model (wi.z > 0); SurfaceBsdf mirrors back-side queries to the front.
class MetallicRoughnessBsdf : public OpaqueBsdf {
 public:
  // Values are clamped to [0, 1].
  MetallicRoughnessBsdf(const Spectrum& base_color, float metallic, float roughness);
  explicit MetallicRoughnessBsdf(const MetallicRoughnessParams& p)
      : MetallicRoughnessBsdf(p.color, p.metallic, p.roughness) {}

  bool smooth() const { return smooth_; }
  uint32_t lobes() const {
    return kLobeDiffuseReflection | (smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection);
  }
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

  // The base colour: glTF's diffuse colour of the dielectric and f0 of the metal, both what
  // OIDN asks for (docs/output-layers.md).
  Spectrum albedo() const { return base_color_; }

  // The constants the surface stage's lane version reads (render/lane_bsdfs.h).
  float metallic() const { return metallic_; }
  float roughness() const { return roughness_; }
  float alpha() const { return distr_.alpha(); }  // GGX alpha, clamped as the lobe uses it
  float e_avg() const { return e_avg_; }
  float dielectric_avg() const { return dielectric_avg_; }
  const Spectrum& f_ms() const { return f_ms_; }

  // The dielectric's specular reflectance f0 (ior 1.5, as glTF: ((1.5 - 1) / (1.5 + 1))^2).
  static constexpr float kDielectricF0 = 0.04f;

 private:
  // The one body of eval (kEval), pdf (kPdf) and eval_pdf (both).
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // E and E5 of the Fresnel-free specular lobe at cos theta = mu (the mirror's in closed form).
  MicrofacetAlbedo lobe_albedo(float mu) const;
  // The specular layer's Fresnel-weighted directional albedo, from lobe_albedo(mu): dielectric
  // and metal mixed by metallic.
  Spectrum specular_albedo(const MicrofacetAlbedo& a) const;
  // f cos_o of the diffuse-like part (dielectric base and metal multiple scattering), from
  // lobe_albedo of mu_i and of mu_o.
  Spectrum diffuse_value(const MicrofacetAlbedo& ai, const MicrofacetAlbedo& ao, float mu_o) const;
  // Fresnel of the specular lobe at wi.h, dielectric and metal mixed by metallic.
  Spectrum fresnel(float cos_ih) const;
  // Probability of sampling the specular lobe for wi given the enabled lobes; `ai`, if the
  // caller has it, is lobe_albedo(mu_i).
  float specular_probability(const BsdfContext& ctx, float mu_i,
                             std::optional<MicrofacetAlbedo> ai = std::nullopt) const;
  uint32_t specular_lobe() const { return smooth_ ? kLobeDeltaReflection : kLobeGlossyReflection; }

  Spectrum base_color_;
  float metallic_;
  float roughness_;
  bool smooth_;
  GgxDistribution distr_;
  // Per-material constants of the compensation terms (roughness-dependent averages).
  float e_avg_;           // E_avg of the Fresnel-free lobe
  float e5_avg_;          // its Schlick part
  float dielectric_avg_;  // E_F,avg for f0 = 0.04
  Spectrum f_ms_;         // F_ms of the metal
};

}  // namespace penumbra
