#pragma once
// The materials as plain parameters: what api/ produces from JSON and a Material is built from.
// No BSDF code here, so the layers above the renderer see values, not the interface.
#include <variant>

#include "renderer/core/math.h"

namespace penumbra {

// Plain parameters of each material. Roughness is the user's r in [0,1]; GGX alpha = r^2.
struct DiffuseParams {
  Spectrum color{0.5f};
};
struct ConductorParams {
  Spectrum color{1.f};  // constant (angle-independent) Fresnel reflectance
  float roughness = 0.f;
};
struct DielectricParams {
  float ior = 1.5f;     // interior ior; exterior is 1
  float roughness = 0.f;
  Spectrum absorption{0.f};  // sigma_a per unit length inside (Beer-Lambert), applied by the integrator
};
struct PlasticParams {
  Spectrum color{0.5f};  // diffuse reflectance of the base
  float ior = 1.5f;      // coating ior
  float roughness = 0.f;
};
using MaterialParams = std::variant<DiffuseParams, ConductorParams, DielectricParams, PlasticParams>;

}  // namespace penumbra
