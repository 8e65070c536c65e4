#pragma once
// Dielectric Fresnel equations and the reflect / refract helpers of the local shading frame.
#include "renderer/math.h"

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

// Hemispherical (cosine-weighted) average of the Fresnel reflectance, 2 \int F(mu) mu dmu, for
// light arriving from the side where the relative ior is `eta`. Polynomial fits: Egan & Hilgeman
// 1973 for eta < 1, d'Eon & Irving 2011 ("A quantized-diffusion model for rendering translucent
// materials", eq. for 2C1) for eta >= 1; the same choice Mitsuba 3 makes.
float fresnel_diffuse_reflectance(float eta);

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
