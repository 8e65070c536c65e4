#pragma once
// The BSDF at one surface point: one model of the closed set with its parameters (constant, or
// looked up from textures at the hit), the two-sided handling of opaque models, and an optional
// normal map. What the integrators evaluate and sample; conventions in bsdf.h.
#include <optional>
#include <variant>

#include "renderer/core/frame.h"
#include "renderer/materials/bsdf.h"
#include "renderer/materials/conductor.h"
#include "renderer/materials/dielectric.h"
#include "renderer/materials/diffuse.h"
#include "renderer/materials/metallic_roughness.h"
#include "renderer/materials/plastic.h"

namespace penumbra {

using BsdfModel = std::variant<DiffuseBsdf, ConductorBsdf, DielectricBsdf, PlasticBsdf,
                               MetallicRoughnessBsdf>;

class SurfaceBsdf {
 public:
  explicit SurfaceBsdf(const BsdfModel& model);

  // Normal mapping as Mitsuba 3.9's `normalmap` adapter with its defaults (src/bsdfs/
  // normalmap.cpp): `n` = 2 rgb - 1 from the map, in the shading frame whose x axis follows dp/du
  // (the integrator builds that frame for normal-mapped materials). The model is evaluated in
  // the perturbed frame; a direction must lie on the same side of the perturbed and the
  // unperturbed normal; a perturbed normal that faces away from wi is mirrored about the
  // unperturbed one (flip_invalid_normals, after Schüssler et al. 2017); and the response is
  // scaled by the shadowing term of Estevez et al. 2019 (Ray Tracing Gems ch. 12) that softens
  // the terminator.
  void set_mapped_normal(const vec3& n);
  bool normal_mapped() const { return normal_mapped_; }
  // The normal set_mapped_normal set (2 rgb - 1 as the map gives it, not normalised).
  const vec3& mapped_normal() const { return mapped_normal_; }
  // The normal the model is evaluated with for incident direction wi, in the shading frame:
  // +z, or the mapped normal as perturbed_frame adjusts it (for the "normal" output layer).
  vec3 shading_normal(const vec3& wi) const {
    return normal_mapped_ ? perturbed_frame(wi).n : vec3(0.f, 0.f, 1.f);
  }

  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // Both at once, equal to the bit to eval and pdf (next-event estimation asks for both).
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // u_lobe picks a lobe, u the direction; both in [0,1).
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

  // Union of BsdfLobe bits this BSDF can produce. Inline: the integrator asks at every vertex.
  uint32_t lobes() const {
    return std::visit([](const auto& m) { return m.lobes(); }, model_);
  }
  // Opaque models are two-sided (the back behaves as the front); oriented ones are not.
  bool two_sided() const { return two_sided_; }
  // Beer-Lambert sigma_a of the interior, zero for everything that does not absorb inside.
  Spectrum absorption() const;
  // The surface colour of the "albedo" output layer (each model's albedo(), in [0, 1]).
  Spectrum albedo() const;
  const BsdfModel& model() const { return model_; }

 private:
  // The one body of eval (kEval), pdf (kPdf) and eval_pdf (both): two-sided handling, then the
  // model directly or through the normal map.
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // The front-side answers with a normal map (wi mirrored to the front already for two-sided
  // models). Without one, eval / pdf / sample visit the model directly: the common case stays
  // one call deep, with the inline models (DiffuseBsdf) inlined into it (docs/performance.md).
  template <bool kEval, bool kPdf>
  BsdfEvalPdf evaluate_mapped(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  std::optional<BsdfSample> sample_mapped(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                          const vec2& u) const;
  // The normal map's frame in shading-frame coordinates, for incident direction wi.
  Frame perturbed_frame(const vec3& wi) const;

  BsdfModel model_;
  bool two_sided_;
  bool normal_mapped_ = false;
  vec3 mapped_normal_{0.f, 0.f, 1.f};
};

}  // namespace penumbra
