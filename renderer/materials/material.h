#pragma once
// A material ready for rendering: one BSDF model behind a value type.
#include <memory>
#include <optional>

#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"

namespace penumbra {

class CoatingTableCache;

// A material ready for rendering: parameters plus any precomputed data (e.g. the rough plastic
// transmittance tables). Immutable after construction and safe to share between threads.
class Material {
 public:
  // `cache` shares precomputed tables between the materials of one scene build (may be null).
  explicit Material(const MaterialParams& params, CoatingTableCache* cache = nullptr);
  ~Material();
  Material(Material&&) noexcept;
  Material& operator=(Material&&) noexcept;

  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // u_lobe picks a lobe, u the direction; both in [0,1).
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

  uint32_t lobes() const;  // union of BsdfLobe bits this material can produce
  bool has_transmission() const { return (lobes() & kLobeTransmission) != 0; }
  // Opaque models are two-sided (the back behaves as the front); oriented ones are not.
  bool two_sided() const;
  // Beer-Lambert sigma_a of the interior, zero for everything that does not absorb inside.
  Spectrum absorption() const;
  bool has_absorption() const { return !is_black(absorption()); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
