#pragma once
// Lambertian reflection.
#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"

namespace penumbra {

// Front-side model (wi.z > 0); Material mirrors back-side queries to the front.
class DiffuseBsdf : public OpaqueBsdf {
 public:
  explicit DiffuseBsdf(const Spectrum& color) : color_(color) {}
  explicit DiffuseBsdf(const DiffuseParams& params) : DiffuseBsdf(params.color) {}

  uint32_t lobes() const { return kLobeDiffuseReflection; }
  // The first-hit albedo of the "albedo" output (docs/output-layers.md): the reflectance.
  Spectrum albedo() const { return color_; }
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

 private:
  Spectrum color_;
};

}  // namespace penumbra
