#include "renderer/materials/diffuse.h"

#include "renderer/sampling/sampling.h"

namespace penumbra {

Spectrum DiffuseBsdf::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (!(ctx.lobes & kLobeDiffuseReflection) || wi.z <= 0.f || wo.z <= 0.f) return Spectrum(0.f);
  return color_ * (kInvPi * wo.z);
}

float DiffuseBsdf::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  if (!(ctx.lobes & kLobeDiffuseReflection) || wi.z <= 0.f || wo.z <= 0.f) return 0.f;
  return cosine_hemisphere_pdf(wo);
}

std::optional<BsdfSample> DiffuseBsdf::sample(const BsdfContext& ctx, const vec3& wi, float,
                                              const vec2& u) const {
  if (!(ctx.lobes & kLobeDiffuseReflection) || wi.z <= 0.f) return std::nullopt;
  BsdfSample bs;
  bs.wo = square_to_cosine_hemisphere(u);
  bs.pdf = cosine_hemisphere_pdf(bs.wo);
  if (!(bs.pdf > 0.f)) return std::nullopt;
  // f cos / pdf = (color / pi) cos / (cos / pi).
  bs.weight = color_;
  bs.lobe = kLobeDiffuseReflection;
  bs.eta = 1.f;
  return bs;
}

}  // namespace penumbra
