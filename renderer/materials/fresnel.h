#pragma once
// Dielectric Fresnel equations and the reflect / refract helpers of the local shading frame.
#include "renderer/core/math.h"

namespace penumbra {

struct FresnelDielectric {
  float reflectance;  // unpolarised Fresnel reflectance F
  float cos_t;        // cosine of the transmitted direction, sign opposite to cos_i (0 on TIR)
  float eta_it;       // relative ior eta_t / eta_i across the interface seen from the incident side
  float eta_ti;       // 1 / eta_it
};

// Exact unpolarised Fresnel reflectance of a smooth dielectric interface (Born & Wolf; Walter et
// al. 2007 eq. 22 in its equivalent form). `cos_i` is signed w.r.t. the normal; `eta` is the
// interior ior over the exterior ior. cos_i < 0 means the incident side is the interior.
// eta == 1 is an index-matched (invisible) interface: F = 0. Total internal reflection: F = 1.
FresnelDielectric fresnel_dielectric(float cos_i, float eta);

// Hemispherical (cosine-weighted) averages of a smooth interface for light arriving from the side
// where the relative ior is `eta` (> 0): the diffuse reflectance fdr = 2 \int_0^1 F(mu) mu dmu and
// the diffuse transmittance 1 - fdr, by quadrature of the exact Fresnel equations (not a fitted
// polynomial). The transmittance is integrated directly, so it keeps its relative precision where
// it is tiny (eta -> 0 or infinity, where 1 / (1 - fdr) amplifies any error); the reflectance is
// 1 minus it. Exact to ~1e-15 (see fresnel.cpp); a few hundred Fresnel evaluations, so callers
// that construct often should cache per eta.
struct DiffuseFresnel {
  double reflectance;
  double transmittance;
};
DiffuseFresnel fresnel_diffuse(double eta);

// Mirror reflection about the local normal +z (both directions point away).
inline vec3 reflect_local(const vec3& wi) { return vec3(-wi.x, -wi.y, wi.z); }
// Mirror reflection about the unit microfacet normal m.
inline vec3 reflect(const vec3& wi, const vec3& m) { return 2.f * glm::dot(wi, m) * m - wi; }
// Refraction through a surface with unit normal m (Snell's law), given the signed transmitted
// cosine and the ratio eta_ti from fresnel_dielectric(dot(wi, m), eta).
inline vec3 refract(const vec3& wi, const vec3& m, float cos_t, float eta_ti) {
  return m * (glm::dot(wi, m) * eta_ti + cos_t) - wi * eta_ti;
}
inline vec3 refract_local(const vec3& wi, float cos_t, float eta_ti) {
  return vec3(-eta_ti * wi.x, -eta_ti * wi.y, cos_t);
}

}  // namespace penumbra
