#pragma once
// A material ready for rendering: its BSDF where every parameter is constant, and the textures
// it looks up per hit where some parameter varies over the surface.
#include <memory>
#include <optional>

#include "renderer/materials/bsdf.h"
#include "renderer/materials/material_params.h"
#include "renderer/textures/texture.h"

namespace penumbra {

class CoatingTableCache;
class ImageFloatTexture;
class ImageSpectrumTexture;
class SurfaceBsdf;
class TextureImageCache;

// Immutable after construction and safe to share between threads.
//
// Per hit the integrator asks `varies()`: if false (no texture, no normal map) it uses `bsdf()`,
// built once, exactly as before textures existed; if true it asks `bsdf_at(query)` for a BSDF
// with the textures looked up there (pbrt-v4's Material::GetBSDF). A constant parameter is never
// a texture object, so an untextured material costs no lookup and no virtual call.
class Material {
 public:
  // `coatings` shares precomputed coating tables and `images` decoded texture images between the
  // materials of one scene; both must outlive the material. Either may be null: the material then
  // keeps its own. Throws ImageIoError if a texture's image cannot be read.
  explicit Material(const MaterialParams& params, CoatingTableCache* coatings = nullptr,
                    TextureImageCache* images = nullptr);
  ~Material();
  Material(Material&&) noexcept;
  Material& operator=(Material&&) noexcept;

  // The BSDF with every texture replaced by 1 (its factor alone): the BSDF everywhere for an
  // untextured material.
  const SurfaceBsdf& bsdf() const { return *bsdf_; }
  // Some parameter is textured or a normal map is set: ask bsdf_at at each hit.
  bool varies() const { return varies_; }
  // The BSDF needs the shading frame's tangent along dp/du (SurfaceBsdf::set_mapped_normal).
  bool normal_mapped() const { return normal_mapped_; }
  // The BSDF at a surface point, its textures looked up there.
  SurfaceBsdf bsdf_at(const TextureQuery& q) const;
  // Only the normal map varies (no parameter is textured): bsdf_at(q) is bsdf() with
  // mapped_normal_at(q) set, so a caller that holds bsdf()'s parameters needs only that normal.
  bool only_normal_varies() const { return varies_ && !parameters_vary_; }
  // Of the parameters only the colour is textured, on a diffuse, conductor or plastic model (a
  // normal map may be set too): bsdf_at(q) is bsdf() with the colour color_at(q) (for the
  // plastic, with_color: its sampling weight follows the colour) and the normal
  // mapped_normal_at(q), every other parameter bsdf()'s, so a caller that holds bsdf()'s
  // parameters needs only that colour (no BSDF built per hit).
  bool only_color_varies() const { return only_color_varies_; }
  // The colour at q as bsdf_at sets it: the factor times the texture clamped to [0, 1].
  Spectrum color_at(const TextureQuery& q) const;
  // Where only_color_varies(): the colour's image texture, whose eval_many looks up many points
  // at once; else nullptr. color_at(q) is color_of_texel(its eval(q)).
  const ImageSpectrumTexture* color_image() const;
  // The colour of a looked-up texel: the factor times the texel clamped to [0, 1].
  Spectrum color_of_texel(const Spectrum& texel) const;
  // Likewise for a conductor's or a dielectric's roughness as the only textured parameter:
  // bsdf_at(q) is the model built with roughness_of_texel(roughness_image()->eval(q)) (and the
  // map's normal), every other parameter bsdf()'s. nullptr for any other material.
  const ImageFloatTexture* roughness_image() const;
  float roughness_of_texel(float texel) const;
  // The normal map's normal at q as bsdf_at sets it (SurfaceBsdf::mapped_normal): 2 rgb - 1,
  // its x and y times glTF's normal scale. Only where normal_mapped().
  vec3 mapped_normal_at(const TextureQuery& q) const;
  // The normal map's image texture (nullptr without one) and the normal of a looked-up texel:
  // mapped_normal_at(q) is normal_of_texel(normal_image()->eval(q)).
  const ImageSpectrumTexture* normal_image() const;
  vec3 normal_of_texel(const Spectrum& texel) const;
  // Any textured parameters: their image textures (nullptr where the parameter is constant), and
  // bsdf_at's BSDF built from their texels (those of absent textures unread), without the normal
  // map: bsdf_at(q) is bsdf_of_texels(color_texture()->eval(q), roughness_texture()->eval(q),
  // metallic_texture()->eval(q)) with the normal mapped_normal_at(q). So a caller can look up
  // many points' texels at once (eval_many) and build each point's BSDF from them.
  const ImageSpectrumTexture* color_texture() const;
  const ImageFloatTexture* roughness_texture() const;
  const ImageFloatTexture* metallic_texture() const;
  SurfaceBsdf bsdf_of_texels(const Spectrum& color, float roughness, float metallic) const;

  // bsdf()'s answers (tests and untextured materials).
  Spectrum eval(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  float pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  BsdfEvalPdf eval_pdf(const BsdfContext& ctx, const vec3& wi, const vec3& wo) const;
  // u_lobe picks a lobe, u the direction; both in [0,1).
  std::optional<BsdfSample> sample(const BsdfContext& ctx, const vec3& wi, float u_lobe,
                                   const vec2& u) const;

  // Union of BsdfLobe bits this material can produce anywhere on the surface (a roughness
  // texture that reaches 0 adds the Dirac lobes of the smooth limit).
  uint32_t lobes() const { return lobes_; }
  bool has_transmission() const { return (lobes() & kLobeTransmission) != 0; }
  // Opaque models are two-sided (the back behaves as the front); oriented ones are not.
  bool two_sided() const;
  // Beer-Lambert sigma_a of the interior, zero for everything that does not absorb inside.
  Spectrum absorption() const;
  bool has_absorption() const { return !is_black(absorption()); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const SurfaceBsdf* bsdf_ = nullptr;  // inside impl_ (heap), so moves keep it valid
  bool varies_ = false;
  bool parameters_vary_ = false;  // some parameter (not the normal) is textured
  bool normal_mapped_ = false;
  bool only_color_varies_ = false;
  Spectrum color_factor_{1.f};  // the textured colour's factor (only_color_varies_)
  bool only_roughness_varies_ = false;
  float roughness_factor_ = 1.f;
  uint32_t lobes_ = 0;
};

}  // namespace penumbra
