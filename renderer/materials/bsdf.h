#pragma once
// Material / BSDF interface shared by all integrators.
//
// Conventions (the same as Mitsuba 3, so images and tests line up):
//  * Directions are in the local shading frame (normal = +z), unit length, both pointing AWAY
//    from the surface: `wi` towards where the path came from (camera side), `wo` the sampled /
//    evaluated direction (towards the light).
//  * `eval` returns f(wi, wo) * |cos theta_o| (cosine foreshortening included) over the lobes in
//    the context's mask, excluding Dirac delta lobes (their eval is 0).
//  * `sample` returns the sampling weight f * |cos theta_o| / pdf (for delta lobes: the lobe's
//    reflectance / transmittance divided by the discrete probability of choosing it).
//  * `pdf` is the solid-angle density of `sample` restricted to the same mask, 0 for delta lobes.
//  * `eval_pdf` returns both at once (BsdfEvalPdf), equal to the bit to the separate calls.
//  * Opaque materials are two-sided: when wi.z < 0 they mirror both directions to the front.
//    Dielectrics use the orientation: +z points out of the medium (the side with ior 1).
//  * Radiance transport only (no adjoint); the 1/eta^2 factor of refraction is applied to
//    radiance (Veach 1997 ch. 5): sample() weight includes it, eval() too.
#include <cstdint>
#include <optional>

#include "renderer/core/math.h"

namespace penumbra {

enum BsdfLobe : uint32_t {
  kLobeDiffuseReflection = 1u << 0,
  kLobeGlossyReflection = 1u << 1,
  kLobeDeltaReflection = 1u << 2,
  kLobeGlossyTransmission = 1u << 3,
  kLobeDeltaTransmission = 1u << 4,

  kLobeDiffuse = kLobeDiffuseReflection,
  kLobeGlossy = kLobeGlossyReflection | kLobeGlossyTransmission,
  kLobeDelta = kLobeDeltaReflection | kLobeDeltaTransmission,
  kLobeTransmission = kLobeGlossyTransmission | kLobeDeltaTransmission,
  kLobeNonDiffuse = kLobeGlossy | kLobeDelta,
  kLobeAll = 0x1f,
};

struct BsdfContext {
  // Only these lobes take part in eval / pdf / sample. The distributed (Cook) integrator uses
  // kLobeDiffuse for direct light only and kLobeNonDiffuse for recursion.
  uint32_t lobes = kLobeAll;
};

struct BsdfSample {
  vec3 wo;
  Spectrum weight;   // f * |cos theta_o| / pdf
  float pdf = 0.f;   // solid-angle pdf (restricted to the context mask); 0 marks a delta lobe
  uint32_t lobe = 0; // exactly one BsdfLobe bit: the lobe that was sampled
  float eta = 1.f;   // relative ior crossed along wo (1 for reflection), for Russian roulette
};

// f(wi, wo) |cos theta_o| and the pdf of the same direction pair under one context: what eval and
// pdf return, from one call that computes the terms they share (the half vector, D, G1(wi),
// Fresnel, a coating's transmittance) once, as Mitsuba 3's BSDF::eval_pdf. Every model's
// eval_pdf gives exactly (bit for bit) its eval and its pdf: the three share one body.
struct BsdfEvalPdf {
  Spectrum f{0.f};
  float pdf = 0.f;
};

// The capability answers shared by every opaque model (all but the dielectric): two-sided, no
// interior to absorb in. A model class answers two_sided() and absorption() itself or inherits
// these; Material and the scene build ask the model, never its type.
struct OpaqueBsdf {
  static constexpr bool two_sided() { return true; }
  Spectrum absorption() const { return Spectrum(0.f); }
};

}  // namespace penumbra
