// Materials whose parameters are textures: factor x texture looked up per hit, clamped to the
// parameter's range; a roughness texture that reaches 0 adds the smooth model's Dirac lobes; a
// textured plastic shares its coating tables instead of copying them; untextured materials never
// vary.
#include <gtest/gtest.h>

#include "renderer/materials/coating_tables.h"
#include "renderer/materials/conductor.h"
#include "renderer/materials/dielectric.h"
#include "renderer/materials/material.h"
#include "renderer/materials/plastic.h"
#include "renderer/materials/surface_bsdf.h"
#include "renderer/textures/image_texture.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

const vec3 kWi = glm::normalize(vec3(0.2f, 0.1f, 0.9f));
const vec3 kWo = glm::normalize(vec3(-0.3f, 0.2f, 0.8f));

TextureQuery at(float u, float v) { return TextureQuery{vec3(0.f), vec2(u, v), 0.f}; }

// A 2 x 1 float image: left texel `l`, right texel `r` (RGB), looked up nearest.
ImageTextureDesc two_texels(const TempFolder& dir, const std::string& name, const Spectrum& l,
                            const Spectrum& r) {
  const std::string path = dir.file(name);
  write_test_image(path, 2, 1, 3, {l.x, l.y, l.z, r.x, r.y, r.z});
  ImageTextureDesc d;
  d.path = path;
  d.colorspace = TextureColorspace::kLinear;
  d.filter = TextureFilter::kNearest;
  return d;
}

TEST(TexturedMaterial, ConstantMaterialsDoNotVary) {
  for (const MaterialParams& p :
       {MaterialParams(DiffuseParams{}), MaterialParams(ConductorParams{}),
        MaterialParams(DielectricParams{}), MaterialParams(PlasticParams{})}) {
    const Material m(p);
    EXPECT_FALSE(m.varies());
    EXPECT_FALSE(m.normal_mapped());
  }
}

TEST(TexturedMaterial, DiffuseColourIsFactorTimesTexture) {
  TempFolder dir("textured_diffuse");
  DiffuseParams p;
  p.color = Spectrum(0.5f);
  p.color_texture = two_texels(dir, "c.exr", Spectrum(1.f, 0.f, 0.f), Spectrum(0.2f, 0.4f, 0.8f));
  const Material m(p);
  EXPECT_TRUE(m.varies());
  EXPECT_FALSE(m.normal_mapped());
  const float cos_o = kWo.z;
  EXPECT_EQ(m.bsdf_at(at(0.25f, 0.5f)).eval(BsdfContext{}, kWi, kWo),
            Spectrum(0.5f, 0.f, 0.f) * (kInvPi * cos_o));
  EXPECT_EQ(m.bsdf_at(at(0.75f, 0.5f)).eval(BsdfContext{}, kWi, kWo),
            Spectrum(0.1f, 0.2f, 0.4f) * (kInvPi * cos_o));
  // bsdf() is the factor alone.
  EXPECT_EQ(m.bsdf().eval(BsdfContext{}, kWi, kWo), Spectrum(0.5f) * (kInvPi * cos_o));
}

TEST(TexturedMaterial, ReflectanceTexelsAreClampedToOne) {
  TempFolder dir("textured_clamp");
  DiffuseParams p;
  p.color = Spectrum(1.f);
  p.color_texture = two_texels(dir, "c.exr", Spectrum(3.f, -1.f, 0.5f), Spectrum(0.f));
  const Material m(p);
  EXPECT_EQ(m.bsdf_at(at(0.25f, 0.5f)).eval(BsdfContext{}, kWi, kWo),
            Spectrum(1.f, 0.f, 0.5f) * (kInvPi * kWo.z));
}

TEST(TexturedMaterial, RoughnessTextureReachingZeroIsSmoothThere) {
  TempFolder dir("textured_rough");
  ConductorParams p;
  p.color = Spectrum(0.9f);
  p.roughness = 1.f;
  p.roughness_texture = two_texels(dir, "r.exr", Spectrum(0.f), Spectrum(0.5f));
  const Material m(p);
  EXPECT_EQ(m.lobes(), uint32_t(kLobeDeltaReflection | kLobeGlossyReflection));
  const SurfaceBsdf smooth = m.bsdf_at(at(0.25f, 0.5f)), rough = m.bsdf_at(at(0.75f, 0.5f));
  EXPECT_EQ(smooth.lobes(), uint32_t(kLobeDeltaReflection));
  EXPECT_EQ(rough.lobes(), uint32_t(kLobeGlossyReflection));
  // The rough half is exactly the constant material of roughness 0.5.
  EXPECT_EQ(rough.eval(BsdfContext{}, kWi, kWo),
            Material(ConductorParams{Spectrum(0.9f), 0.5f}).eval(BsdfContext{}, kWi, kWo));
  // The second channel, scaled: roughness 0.4 * 0.5.
  p.roughness = 0.4f;
  p.roughness_texture = two_texels(dir, "g.exr", Spectrum(0.f, 0.5f, 0.f), Spectrum(0.f));
  p.roughness_texture->channel = 1;
  EXPECT_EQ(Material(p).bsdf_at(at(0.25f, 0.5f)).eval(BsdfContext{}, kWi, kWo),
            Material(ConductorParams{Spectrum(0.9f), 0.2f}).eval(BsdfContext{}, kWi, kWo));
}

TEST(TexturedMaterial, TexturedPlasticPointsAtSharedTables) {
  TempFolder dir("textured_plastic");
  PlasticParams p;
  p.color = Spectrum(1.f);
  p.roughness = 0.3f;
  p.color_texture = two_texels(dir, "c.exr", Spectrum(0.2f, 0.5f, 0.7f), Spectrum(0.f));
  CoatingTableCache coatings;
  const Material m(p, &coatings);
  EXPECT_EQ(coatings.size(), 1u);
  const SurfaceBsdf b = m.bsdf_at(at(0.25f, 0.5f));
  EXPECT_EQ(coatings.size(), 1u);  // no table computed per hit
  const Material constant(PlasticParams{Spectrum(0.2f, 0.5f, 0.7f), 1.5f, 0.3f}, &coatings);
  EXPECT_EQ(b.eval(BsdfContext{}, kWi, kWo), constant.eval(BsdfContext{}, kWi, kWo));
  EXPECT_EQ(b.pdf(BsdfContext{}, kWi, kWo), constant.pdf(BsdfContext{}, kWi, kWo));
  // A per-hit copy is small: the ~1 KB of tables stay where they are.
  EXPECT_LT(sizeof(PlasticBsdf), 128u);
  EXPECT_LT(sizeof(SurfaceBsdf), 160u);
}

TEST(TexturedMaterial, NormalMapFileGivesTheDecodedNormal) {
  TempFolder dir("textured_normal");
  const vec3 n = glm::normalize(vec3(0.3f, -0.2f, 0.9f));
  const vec3 rgb = 0.5f * (n + vec3(1.f));
  DiffuseParams p;
  p.normal_map = two_texels(dir, "n.exr", rgb, Spectrum(0.5f, 0.5f, 1.f));
  const Material m(p);
  EXPECT_TRUE(m.varies());
  EXPECT_TRUE(m.normal_mapped());
  SurfaceBsdf expected(DiffuseBsdf(p.color));
  expected.set_mapped_normal(n);
  const Spectrum f = m.bsdf_at(at(0.25f, 0.5f)).eval(BsdfContext{}, kWi, kWo);
  const Spectrum g = expected.eval(BsdfContext{}, kWi, kWo);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], g[c], 1e-6f);
  // The right texel is flat: the plain model.
  EXPECT_EQ(m.bsdf_at(at(0.75f, 0.5f)).eval(BsdfContext{}, kWi, kWo),
            m.bsdf().eval(BsdfContext{}, kWi, kWo));
}

// A material whose only texture is its normal map is its constant BSDF with the map's normal
// (bsdf_at's shortcut, and the surface stages take only that normal): the same BSDF to the bit
// as the general lookup gives once some parameter is textured by an image of ones.
TEST(TexturedMaterial, NormalMapAloneIsTheConstantBsdfWithTheMapsNormal) {
  TempFolder dir("textured_normal_only");
  const vec3 n = glm::normalize(vec3(0.3f, -0.2f, 0.9f));
  const ImageTextureDesc map = two_texels(dir, "n.exr", 0.5f * (n + vec3(1.f)), Spectrum(0.5f, 0.4f, 1.f));
  const ImageTextureDesc ones = two_texels(dir, "one.exr", Spectrum(1.f), Spectrum(1.f));
  DiffuseParams diffuse{Spectrum(0.8f, 0.6f, 0.4f)};
  ConductorParams conductor{Spectrum(0.9f, 0.8f, 0.7f), 0.35f};
  PlasticParams plastic{Spectrum(0.5f, 0.3f, 0.2f), 1.5f, 0.3f};
  DielectricParams dielectric{1.5f, 0.4f};
  MetallicRoughnessParams gltf{Spectrum(0.7f, 0.6f, 0.3f), 0.4f, 0.5f};
  gltf.normal_scale = 0.6f;
  std::vector<std::pair<MaterialParams, MaterialParams>> cases;  // normal map alone, and with ones
  auto add = [&](auto p, auto with_ones) {
    p.normal_map = map;
    auto q = p;
    with_ones(q);
    cases.emplace_back(p, q);
  };
  add(diffuse, [&](auto& q) { q.color_texture = ones; });
  add(conductor, [&](auto& q) { q.roughness_texture = ones; });
  add(plastic, [&](auto& q) { q.color_texture = ones; });
  add(dielectric, [&](auto& q) { q.roughness_texture = ones; });
  add(gltf, [&](auto& q) { q.metallic_texture = ones; });
  CoatingTableCache coatings;
  for (const auto& [alone, general] : cases) {
    const Material a(alone, &coatings), g(general, &coatings);
    EXPECT_TRUE(a.only_normal_varies());
    EXPECT_FALSE(g.only_normal_varies());
    for (const float u : {0.25f, 0.75f}) {
      const SurfaceBsdf x = a.bsdf_at(at(u, 0.5f)), y = g.bsdf_at(at(u, 0.5f));
      EXPECT_EQ(x.mapped_normal(), y.mapped_normal());
      EXPECT_EQ(x.mapped_normal(), a.mapped_normal_at(at(u, 0.5f)));
      EXPECT_EQ(x.lobes(), y.lobes());
      EXPECT_EQ(x.albedo(), y.albedo());
      for (const vec3& wo : {kWo, vec3(kWo.x, kWo.y, -kWo.z)}) {
        EXPECT_EQ(x.eval(BsdfContext{}, kWi, wo), y.eval(BsdfContext{}, kWi, wo));
        EXPECT_EQ(x.pdf(BsdfContext{}, kWi, wo), y.pdf(BsdfContext{}, kWi, wo));
      }
      for (const float u_lobe : {0.1f, 0.6f, 0.95f}) {
        const auto sx = x.sample(BsdfContext{}, kWi, u_lobe, vec2(0.3f, 0.7f));
        const auto sy = y.sample(BsdfContext{}, kWi, u_lobe, vec2(0.3f, 0.7f));
        ASSERT_EQ(sx.has_value(), sy.has_value());
        if (!sx) continue;
        EXPECT_EQ(sx->wo, sy->wo);
        EXPECT_EQ(sx->weight, sy->weight);
        EXPECT_EQ(sx->pdf, sy->pdf);
      }
    }
  }
}

// A material whose only textured parameter is its colour, on a diffuse, conductor or plastic
// model, is its constant BSDF with the colour looked up (the surface stages take only color_at,
// the plastic's sampling weight with it, and the map's normal where there is one): the colour to
// the bit, with texels beyond [0, 1] clamped; any other texture or model takes the general lookup.
TEST(TexturedMaterial, ColourAloneIsTheConstantBsdfWithTheTexturesColour) {
  TempFolder dir("textured_colour_only");
  const ImageTextureDesc colour =
      two_texels(dir, "c.exr", Spectrum(0.3f, 1.7f, 0.55f), Spectrum(0.9f, 0.05f, -0.2f));
  const ImageTextureDesc other = two_texels(dir, "o.exr", Spectrum(0.4f), Spectrum(0.6f));
  DiffuseParams diffuse{Spectrum(0.8f, 0.6f, 0.4f)};
  diffuse.color_texture = colour;
  ConductorParams conductor{Spectrum(0.9f, 0.8f, 0.7f), 0.35f};
  conductor.color_texture = colour;
  PlasticParams plastic{Spectrum(0.5f, 0.3f, 0.2f), 1.5f, 0.3f};
  plastic.color_texture = colour;
  DiffuseParams mapped = diffuse;  // a normal map besides: the colour is still looked up alone
  mapped.normal_map = other;
  CoatingTableCache coatings;
  const std::pair<MaterialParams, Spectrum> cases[] = {{diffuse, diffuse.color},
                                                       {conductor, conductor.color},
                                                       {plastic, plastic.color},
                                                       {mapped, mapped.color}};
  for (const auto& [p, factor] : cases) {
    const Material m(p, &coatings);
    ASSERT_TRUE(m.only_color_varies());
    // The texels clamped to [0, 1], times the factor.
    EXPECT_EQ(m.color_at(at(0.25f, 0.5f)), factor * Spectrum(0.3f, 1.f, 0.55f));
    EXPECT_EQ(m.color_at(at(0.75f, 0.5f)), factor * Spectrum(0.9f, 0.05f, 0.f));
    for (const float u : {0.25f, 0.75f}) {
      const SurfaceBsdf b = m.bsdf_at(at(u, 0.5f));
      EXPECT_EQ(m.color_at(at(u, 0.5f)), b.albedo());
      EXPECT_EQ(b.lobes(), m.bsdf().lobes());
      ASSERT_EQ(b.normal_mapped(), m.normal_mapped());
      if (m.normal_mapped()) EXPECT_EQ(b.mapped_normal(), m.mapped_normal_at(at(u, 0.5f)));
      // A plastic's sampling weight follows the colour: with_color on the constant BSDF.
      if (const auto* p = std::get_if<PlasticBsdf>(&m.bsdf().model()))
        EXPECT_EQ(std::get<PlasticBsdf>(b.model()).specular_sampling_weight(),
                  p->with_color(m.color_at(at(u, 0.5f))).specular_sampling_weight());
    }
  }
  ConductorParams rough = conductor;
  rough.roughness_texture = other;
  MetallicRoughnessParams gltf{Spectrum(0.7f, 0.6f, 0.3f), 0.4f, 0.5f};
  gltf.color_texture = colour;
  DielectricParams glass{1.5f, 0.2f};
  DiffuseParams normal_only{Spectrum(0.5f)};
  normal_only.normal_map = other;
  for (const MaterialParams& p : {MaterialParams(rough), MaterialParams(gltf),
                                  MaterialParams(glass), MaterialParams(normal_only)})
    EXPECT_FALSE(Material(p, &coatings).only_color_varies());
  EXPECT_FALSE(Material(DiffuseParams{Spectrum(0.5f)}, &coatings).only_color_varies());
}

// Likewise a conductor's or dielectric's roughness as its only texture: the model built with
// roughness_of_texel of the texel is bsdf_at's (the stages derive the GGX alpha and the smooth
// limit from it); a texel of 0 makes the lobe smooth there.
TEST(TexturedMaterial, RoughnessAloneIsTheModelWithTheTexturesRoughness) {
  TempFolder dir("textured_roughness_only");
  ImageTextureDesc rough = two_texels(dir, "r.exr", Spectrum(0.6f), Spectrum(0.f));
  ConductorParams conductor{Spectrum(0.9f, 0.8f, 0.7f), 0.7f};
  conductor.roughness_texture = rough;
  DielectricParams dielectric{1.5f, 0.9f};
  dielectric.roughness_texture = rough;
  CoatingTableCache coatings;
  DielectricParams mapped = dielectric;  // a normal map besides: the roughness still alone
  mapped.normal_map = rough;
  const Material c(conductor, &coatings), d(dielectric, &coatings), dm(mapped, &coatings);
  for (const Material* m : {&c, &d, &dm}) {
    ASSERT_NE(m->roughness_image(), nullptr);
    EXPECT_EQ(m->color_image(), nullptr);
    for (const float u : {0.25f, 0.75f}) {
      const TextureQuery q = at(u, 0.5f);
      const float r = m->roughness_of_texel(m->roughness_image()->eval(q));
      const SurfaceBsdf b = m->bsdf_at(q);
      const float alpha = roughness_to_alpha(r);
      auto check = [&](const auto& model) {
        EXPECT_EQ(model.smooth(), alpha < kMinMicrofacetAlpha);
        EXPECT_EQ(model.alpha(), GgxDistribution(alpha).alpha());
      };
      if (m == &c)
        check(std::get<ConductorBsdf>(b.model()));
      else
        check(std::get<DielectricBsdf>(b.model()));
      ASSERT_EQ(b.normal_mapped(), m->normal_mapped());
      if (m->normal_mapped()) EXPECT_EQ(b.mapped_normal(), m->mapped_normal_at(q));
    }
    // The factor times the texel: 0.7 x 0.6 and 0.9 x 0.6; 0 on the right texel (smooth).
    EXPECT_EQ(m->roughness_of_texel(0.6f), (m == &c ? 0.7f : 0.9f) * 0.6f);
    EXPECT_EQ(m->roughness_of_texel(1.5f), m == &c ? 0.7f : 0.9f);
  }
  ConductorParams with_colour = conductor;
  with_colour.color_texture = rough;
  MetallicRoughnessParams gltf{Spectrum(0.7f, 0.6f, 0.3f), 0.4f, 0.5f};
  gltf.roughness_texture = rough;
  for (const MaterialParams& p : {MaterialParams(with_colour), MaterialParams(gltf)})
    EXPECT_EQ(Material(p, &coatings).roughness_image(), nullptr);
}

TEST(TexturedMaterial, MissingImageThrowsNamingTheFile) {
  DiffuseParams p;
  p.color_texture = ImageTextureDesc{"/nonexistent/albedo.png"};
  try {
    const Material m(p);
    ADD_FAILURE() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/albedo.png"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra::test
