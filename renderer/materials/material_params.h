#pragma once
// The materials as plain parameters: what api/ produces from JSON and a Material is built from.
// No BSDF code here, so the layers above the renderer see values, not the interface.
//
// A parameter may also vary over the surface (glTF's factor x texture): the `*_texture` member,
// when set, is looked up at each hit and multiplies the constant beside it (which api/ sets to
// the texture's `scale`, 1 by default). A `normal_map` perturbs the shading normal in the
// tangent frame of the surface's uv parametrisation (Mitsuba 3 `normalmap`).
#include <optional>
#include <variant>

#include "renderer/core/math.h"
#include "renderer/textures/texture_desc.h"

namespace penumbra {

// Plain parameters of each material. Roughness is the user's r in [0,1]; GGX alpha = r^2.
struct DiffuseParams {
  Spectrum color{0.5f};
  std::optional<ImageTextureDesc> color_texture{};
  std::optional<ImageTextureDesc> normal_map{};
};
struct ConductorParams {
  Spectrum color{1.f};  // constant (angle-independent) Fresnel reflectance
  float roughness = 0.f;
  std::optional<ImageTextureDesc> color_texture{};
  std::optional<ImageTextureDesc> roughness_texture{};
  std::optional<ImageTextureDesc> normal_map{};
};
struct DielectricParams {
  float ior = 1.5f;     // interior ior; exterior is 1
  float roughness = 0.f;
  Spectrum absorption{0.f};  // sigma_a per unit length inside (Beer-Lambert), applied by the integrator
  std::optional<ImageTextureDesc> roughness_texture{};
  std::optional<ImageTextureDesc> normal_map{};
};
// The coating's roughness is constant: its tables are precomputed per (roughness, ior), as
// Mitsuba's roughplastic, whose alpha cannot be a texture either.
struct PlasticParams {
  Spectrum color{0.5f};  // diffuse reflectance of the base
  float ior = 1.5f;      // coating ior
  float roughness = 0.f;
  std::optional<ImageTextureDesc> color_texture{};
  std::optional<ImageTextureDesc> normal_map{};
};
using MaterialParams = std::variant<DiffuseParams, ConductorParams, DielectricParams, PlasticParams>;

}  // namespace penumbra
