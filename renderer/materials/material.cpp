// Material: a closed set of BSDF models behind one value type; textured parameters looked up per
// hit (factor x texture, as glTF) and a normal map handed to the SurfaceBsdf.
#include "renderer/materials/material.h"

#include <type_traits>

#include "renderer/materials/coating_tables.h"
#include "renderer/materials/surface_bsdf.h"
#include "renderer/textures/image_texture.h"
#include "renderer/textures/texture_image_cache.h"

namespace penumbra {
namespace {

inline Spectrum clamp01(const Spectrum& s) { return glm::clamp(s, Spectrum(0.f), Spectrum(1.f)); }
inline float clamp01(float v) { return std::clamp(v, 0.f, 1.f); }

BsdfModel make_model(const MaterialParams& params, CoatingTableCache& coatings) {
  return std::visit(
      [&coatings](const auto& p) -> BsdfModel {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, DiffuseParams>)
          return DiffuseBsdf(p);
        else if constexpr (std::is_same_v<P, ConductorParams>)
          return ConductorBsdf(p);
        else if constexpr (std::is_same_v<P, DielectricParams>)
          return DielectricBsdf(p);
        else if constexpr (std::is_same_v<P, MetallicRoughnessParams>)
          return MetallicRoughnessBsdf(p);
        else
          return PlasticBsdf(p, PlasticBsdf::tables_for(p, coatings));
      },
      params);
}

// A params struct's colour texture, if that kind of material has one.
template <typename P>
const std::optional<ImageTextureDesc>* color_texture_of(const P& p) {
  if constexpr (requires { p.color_texture; })
    return &p.color_texture;
  else
    return nullptr;
}

}  // namespace

struct Material::Impl {
  MaterialParams params;
  std::optional<SurfaceBsdf> bsdf;
  // Reflectances and roughness are clamped to [0, 1] after the lookup: a float image may hold
  // any value, and a reflectance above 1 would create energy.
  std::unique_ptr<ImageSpectrumTexture> color;
  std::unique_ptr<ImageFloatTexture> roughness;
  std::unique_ptr<ImageFloatTexture> metallic;
  std::unique_ptr<ImageSpectrumTexture> normal_map;  // linear RGB = (n + 1) / 2
  float normal_scale = 1.f;
  std::unique_ptr<CoatingTableCache> own_coatings;
  std::unique_ptr<TextureImageCache> own_images;
};

Material::Material(const MaterialParams& params, CoatingTableCache* coatings,
                   TextureImageCache* images)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.params = params;
  if (!coatings) coatings = (m.own_coatings = std::make_unique<CoatingTableCache>()).get();
  m.bsdf.emplace(make_model(params, *coatings));
  bsdf_ = &*m.bsdf;
  lobes_ = bsdf_->lobes();

  auto image_cache = [&]() -> TextureImageCache& {
    if (!images) images = (m.own_images = std::make_unique<TextureImageCache>()).get();
    return *images;
  };
  std::visit(
      [&](const auto& p) {
        if (const auto* t = color_texture_of(p); t && *t)
          m.color = make_spectrum_texture(**t, image_cache());
        using P = std::decay_t<decltype(p)>;
        if constexpr (requires { p.roughness_texture; }) {
          if (p.roughness_texture) {
            m.roughness = make_float_texture(*p.roughness_texture, image_cache());
            // Where the texture reaches 0 the model is smooth: its Dirac lobes are possible too.
            P smooth = p;
            smooth.roughness = 0.f;
            lobes_ |= SurfaceBsdf(make_model(smooth, *coatings)).lobes();
          }
        }
        if constexpr (requires { p.metallic_texture; }) {
          if (p.metallic_texture) m.metallic = make_float_texture(*p.metallic_texture, image_cache());
        }
        if (p.normal_map) {
          m.normal_map = make_spectrum_texture(*p.normal_map, image_cache());
          normal_mapped_ = true;
        }
      },
      params);
  parameters_vary_ = m.color || m.roughness || m.metallic;
  varies_ = parameters_vary_ || m.normal_map;
  std::visit(
      [&](const auto& p) {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, DiffuseParams> || std::is_same_v<P, ConductorParams> ||
                      std::is_same_v<P, PlasticParams>) {
          only_color_varies_ = m.color && !m.roughness && !m.metallic;
          color_factor_ = p.color;
        }
        if constexpr (std::is_same_v<P, ConductorParams> || std::is_same_v<P, DielectricParams>) {
          only_roughness_varies_ = m.roughness && !m.color && !m.metallic;
          roughness_factor_ = p.roughness;
        }
      },
      params);
  // glTF's normalTexture.scale multiplies x and y before normalising (glTF 2.0 section 3.9.3);
  // 1 for the other materials.
  m.normal_scale = std::visit(
      [](const auto& p) {
        if constexpr (requires { p.normal_scale; }) return p.normal_scale;
        else return 1.f;
      },
      params);
}

Material::~Material() = default;
Material::Material(Material&&) noexcept = default;
Material& Material::operator=(Material&&) noexcept = default;

vec3 Material::normal_of_texel(const Spectrum& texel) const {
  const float s = impl_->normal_scale;
  return (2.f * texel - vec3(1.f)) * vec3(s, s, 1.f);
}

vec3 Material::mapped_normal_at(const TextureQuery& q) const {
  return normal_of_texel(impl_->normal_map->eval(q));
}

const ImageSpectrumTexture* Material::normal_image() const { return impl_->normal_map.get(); }

Spectrum Material::color_of_texel(const Spectrum& texel) const {
  return color_factor_ * clamp01(texel);
}

Spectrum Material::color_at(const TextureQuery& q) const {
  return color_of_texel(impl_->color->eval(q));
}

const ImageSpectrumTexture* Material::color_image() const {
  return only_color_varies_ ? impl_->color.get() : nullptr;
}

const ImageFloatTexture* Material::roughness_image() const {
  return only_roughness_varies_ ? impl_->roughness.get() : nullptr;
}

float Material::roughness_of_texel(float texel) const { return roughness_factor_ * clamp01(texel); }

const ImageSpectrumTexture* Material::color_texture() const { return impl_->color.get(); }
const ImageFloatTexture* Material::roughness_texture() const { return impl_->roughness.get(); }
const ImageFloatTexture* Material::metallic_texture() const { return impl_->metallic.get(); }

SurfaceBsdf Material::bsdf_at(const TextureQuery& q) const {
  const Impl& m = *impl_;
  if (!parameters_vary_) {
    // The BSDF built once (every model's constructor from its params is the one below with the
    // factors alone), with the map's normal.
    SurfaceBsdf b = *m.bsdf;
    if (m.normal_map) b.set_mapped_normal(mapped_normal_at(q));
    return b;
  }
  SurfaceBsdf b = bsdf_of_texels(m.color ? m.color->eval(q) : Spectrum(0.f),
                                 m.roughness ? m.roughness->eval(q) : 0.f,
                                 m.metallic ? m.metallic->eval(q) : 0.f);
  if (m.normal_map) b.set_mapped_normal(mapped_normal_at(q));
  return b;
}

SurfaceBsdf Material::bsdf_of_texels(const Spectrum& color_texel, float roughness_texel,
                                     float metallic_texel) const {
  const Impl& m = *impl_;
  if (!parameters_vary_) return *m.bsdf;
  auto color = [&](const Spectrum& factor) {
    return m.color ? factor * clamp01(color_texel) : factor;
  };
  auto roughness = [&](float factor) {
    return m.roughness ? factor * clamp01(roughness_texel) : factor;
  };
  return std::visit(
      [&](const auto& p) -> SurfaceBsdf {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, DiffuseParams>)
          return SurfaceBsdf(DiffuseBsdf(color(p.color)));
        else if constexpr (std::is_same_v<P, ConductorParams>)
          return SurfaceBsdf(ConductorBsdf(color(p.color), roughness(p.roughness)));
        else if constexpr (std::is_same_v<P, DielectricParams>)
          return SurfaceBsdf(DielectricBsdf(p.ior, roughness(p.roughness), p.absorption));
        else if constexpr (std::is_same_v<P, MetallicRoughnessParams>)
          return SurfaceBsdf(MetallicRoughnessBsdf(
              color(p.color), m.metallic ? p.metallic * clamp01(metallic_texel) : p.metallic,
              roughness(p.roughness)));
        else  // the coating (and its tables) as built; only the base colour varies
          return SurfaceBsdf(std::get<PlasticBsdf>(m.bsdf->model()).with_color(color(p.color)));
      },
      m.params);
}

Spectrum Material::eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return bsdf_->eval(ctx, wi, wo);
}

float Material::pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return bsdf_->pdf(ctx, wi, wo);
}

BsdfEvalPdf Material::eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const {
  return bsdf_->eval_pdf(ctx, wi, wo);
}

std::optional<BsdfSample> Material::sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                           const vec2& u) const {
  return bsdf_->sample(ctx, wi, u_lobe, u);
}

bool Material::two_sided() const { return bsdf_->two_sided(); }

Spectrum Material::absorption() const { return bsdf_->absorption(); }

}  // namespace penumbra
