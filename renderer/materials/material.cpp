// Material: a closed set of BSDF models behind one value type, with the two-sided handling of
// opaque models done once here.
#include <type_traits>

#include "renderer/materials/material.h"
#include "renderer/materials/conductor.h"
#include "renderer/materials/dielectric.h"
#include "renderer/materials/diffuse.h"
#include "renderer/materials/plastic.h"

namespace penumbra {

namespace {

using BsdfModel = std::variant<DiffuseBsdf, ConductorBsdf, DielectricBsdf, PlasticBsdf>;

BsdfModel make_model(const MaterialParams& params, CoatingTableCache* cache) {
  return std::visit(
      [cache](const auto& p) -> BsdfModel {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, DiffuseParams>) return DiffuseBsdf(p);
        else if constexpr (std::is_same_v<P, ConductorParams>) return ConductorBsdf(p);
        else if constexpr (std::is_same_v<P, DielectricParams>) return DielectricBsdf(p);
        else return PlasticBsdf(p, cache);
      },
      params);
}

// Opaque models are two-sided: seen from the back (wi.z < 0) the surface behaves as its front
// with the frame mirrored through the tangent plane.
inline vec3 flip_z(const vec3& v) { return vec3(v.x, v.y, -v.z); }

}  // namespace

struct Material::Impl {
  BsdfModel model;
  bool two_sided;
};

Material::Material(const MaterialParams& params, CoatingTableCache* cache) {
  BsdfModel model = make_model(params, cache);
  const bool two_sided = std::visit([](const auto& m) { return m.two_sided(); }, model);
  impl_ = std::make_unique<Impl>(Impl{std::move(model), two_sided});
}
Material::~Material() = default;
Material::Material(Material&&) noexcept = default;
Material& Material::operator=(Material&&) noexcept = default;

Spectrum Material::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  const bool flip = impl_->two_sided && wi.z < 0.f;
  const vec3 a = flip ? flip_z(wi) : wi, b = flip ? flip_z(wo) : wo;
  const Spectrum f = std::visit([&](const auto& m) { return m.eval(ctx, a, b); }, impl_->model);
  return is_finite(f) ? f : Spectrum(0.f);
}

float Material::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  const bool flip = impl_->two_sided && wi.z < 0.f;
  const vec3 a = flip ? flip_z(wi) : wi, b = flip ? flip_z(wo) : wo;
  const float p = std::visit([&](const auto& m) { return m.pdf(ctx, a, b); }, impl_->model);
  return std::isfinite(p) ? p : 0.f;
}

std::optional<BsdfSample> Material::sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                           const vec2& u) const {
  const bool flip = impl_->two_sided && wi.z < 0.f;
  const vec3 a = flip ? flip_z(wi) : wi;
  std::optional<BsdfSample> bs =
      std::visit([&](const auto& m) { return m.sample(ctx, a, u_lobe, u); }, impl_->model);
  if (!bs) return std::nullopt;
  if (!is_finite(bs->weight) || !std::isfinite(bs->pdf) || !is_finite(bs->wo)) return std::nullopt;
  if (flip) bs->wo = flip_z(bs->wo);
  return bs;
}

uint32_t Material::lobes() const {
  return std::visit([](const auto& m) { return m.lobes(); }, impl_->model);
}

Spectrum Material::absorption() const {
  return std::visit([](const auto& m) { return m.absorption(); }, impl_->model);
}

bool Material::two_sided() const { return impl_->two_sided; }

}  // namespace penumbra
