#pragma once
// Isotropic GGX / Trowbridge-Reitz microfacet distribution with visible-normal sampling.
//
// D: Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq. 33.
// G: the separable Smith form G(wi, wo, m) = G1(wi, m) * G1(wo, m) (Walter et al. 2007 eq. 23 and
//    34), exactly the masking-shadowing Mitsuba 3's MicrofacetDistribution uses, so images match.
// Sampling: Heitz 2018, "Sampling the GGX Distribution of Visible Normals" (JCGT 7(4)), whose
//    density is D_wi(m) = G1(wi, m) max(0, wi.m) D(m) / wi.z (Heitz 2014 eq. 2 / 2018 eq. 1).
#include "renderer/core/math.h"
#include "renderer/core/quadrature.h"

namespace penumbra {

// Below this alpha a surface is treated as perfectly smooth (a Dirac lobe); at and above it the
// microfacet model is used. Mitsuba clamps its alpha to the same 1e-4.
inline constexpr float kMinMicrofacetAlpha = 1e-4f;

// glTF convention: the user's roughness r in [0,1] maps to GGX alpha = r^2.
inline float roughness_to_alpha(float roughness) { return roughness * roughness; }

// The frame of visible-normal sampling (Heitz 2018, listing 1): the view stretched to the
// alpha = 1 configuration (vh), two tangents around it (t1, t2), and s = (1 + vh.z) / 2, by which
// the far half of the projected hemisphere's disk is squeezed.
struct StretchedView {
  vec3 vh, t1, t2;
  float s;
};
inline StretchedView stretched_view(float alpha, const vec3& wi) {
  StretchedView f;
  f.vh = glm::normalize(vec3(alpha * wi.x, alpha * wi.y, wi.z));
  const float len2 = f.vh.x * f.vh.x + f.vh.y * f.vh.y;
  f.t1 = len2 > 0.f ? vec3(-f.vh.y, f.vh.x, 0.f) / std::sqrt(len2) : vec3(1.f, 0.f, 0.f);
  f.t2 = glm::cross(f.vh, f.t1);
  f.s = 0.5f * (1.f + f.vh.z);
  return f;
}

class GgxDistribution {
 public:
  explicit GgxDistribution(float alpha) : alpha_(std::max(alpha, kMinMicrofacetAlpha)) {}

  float alpha() const { return alpha_; }

  // Normal distribution D(m), normalised so that \int D(m) m.z dm = 1 over the hemisphere.
  float ndf(const vec3& m) const;

  // Smith masking G1(v, m); zero when v sees the back of the microfacet (v.m and v.z differ in sign).
  // The models take the separable masking-shadowing G = G1(wi, m) G1(wo, m).
  float smith_g1(const vec3& v, const vec3& m) const;

  // A microfacet normal distributed as D_wi (visible normals). Requires wi.z > 0.
  vec3 sample_visible(const vec3& wi, const vec2& u) const;

  // Density of sample_visible: D(m) G1(wi, m) |wi.m| / wi.z. Requires wi.z > 0.
  float pdf_visible(const vec3& wi, const vec3& m) const {
    return wi.z <= 0.f ? 0.f : visible_density(ndf(m), smith_g1(wi, m), wi, m);
  }
  // The same from D(m) and G1(wi, m) already at hand (a model's eval_pdf shares them with its
  // value).
  static float visible_density(float d, float g1_wi, const vec3& wi, const vec3& m) {
    return wi.z <= 0.f ? 0.f : d * g1_wi * std::abs(glm::dot(wi, m)) / wi.z;
  }

 private:
  float alpha_;
};

// Directional albedo of the single-scattering rough dielectric interface for an incident
// direction with cosine `cos_i` > 0 on the side where the relative ior is `eta`, computed by
// integrating the visible-normal sampling weights with a res x res Gauss-Legendre rule:
//   reflectance   = E_m[ F(wi.m) G1(wo_r, m) ]
//   transmittance = E_m[ (1 - F(wi.m)) G1(wo_t, m) ]   (energy, without the 1/eta^2 factor)
// These are the integrals Mitsuba 3's roughplastic precomputes (res 32 for eta > 1, else 128).
float rough_dielectric_reflectance(const GgxDistribution& distr, float cos_i, float eta);
float rough_dielectric_transmittance(const GgxDistribution& distr, float cos_i, float eta);

}  // namespace penumbra
