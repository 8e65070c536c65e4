// Texture references in scenes: the {"texture": ...} form of colour, roughness and emission and
// a material's normal_map; defaults (sRGB for colours from integer images, linear otherwise);
// every refusal on the field's pointer; the texture limits at limit and limit + 1, judged on the
// image's header before any pixel is decoded.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>

#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "tests/api/scene_test_util.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

class Textures : public ::testing::Test {
 protected:
  void SetUp() override {
    write_test_image(dir_.file("wood.png"), 4, 4, 3, std::vector<float>(48, 0.5f),
                     OIIO::TypeDesc::UINT8);
    write_test_image(dir_.file("grey.png"), 4, 4, 1, std::vector<float>(16, 0.5f),
                     OIIO::TypeDesc::UINT8);
    write_test_image(dir_.file("hdr.exr"), 2, 2, 3, std::vector<float>(12, 2.f));
    write_test_image(dir_.file("normal.png"), 2, 2, 3, std::vector<float>(12, 0.5f),
                     OIIO::TypeDesc::UINT8);
    assets_.root = dir_.path();
  }

  // The base scene with material "m" replaced by `material`.
  LoadResult load_material(const Json& material, const Limits& limits = {}) {
    Json scene = base_scene();
    scene["materials"]["white"] = material;
    return load_with_assets(scene, limits);
  }
  LoadResult load_with_assets(const Json& scene, const Limits& limits = {}) {
    return load_scene(scene.dump(), limits, {}, assets_);
  }
  std::string canonical(const std::string& name) const {
    return std::filesystem::canonical(dir_.path() / name).string();
  }

  TempFolder dir_{"api_textures_" +
                  std::string(::testing::UnitTest::GetInstance()->current_test_info()->name())};
  AssetFolder assets_;
};

template <typename P>
const P& material0(const LoadResult& r) {
  return std::get<P>(r.request->scene.materials.at(0));
}

TEST_F(Textures, ColourTextureWithDefaults) {
  const LoadResult r = load_material({{"type", "diffuse"}, {"color", {{"texture", "wood.png"}}}});
  EXPECT_LOADS(r);
  const auto& p = material0<DiffuseParams>(r);
  EXPECT_EQ(p.color, Spectrum(1.f));  // the factor: scale 1
  ASSERT_TRUE(p.color_texture);
  EXPECT_EQ(p.color_texture->path, canonical("wood.png"));
  EXPECT_EQ(p.color_texture->colorspace, TextureColorspace::kSrgb);  // 8-bit colour
  EXPECT_EQ(p.color_texture->wrap, TextureWrap::kRepeat);
  EXPECT_EQ(p.color_texture->filter, TextureFilter::kBilinear);
  EXPECT_FALSE(p.normal_map);
}

TEST_F(Textures, FloatImagesAndNonColoursDefaultToLinear) {
  const LoadResult r =
      load_material({{"type", "conductor"},
                     {"color", {{"texture", "hdr.exr"}, {"scale", 0.5}}},
                     {"roughness", {{"texture", "wood.png"}, {"channel", 2}, {"scale", 0.25}}}});
  EXPECT_LOADS(r);
  const auto& p = material0<ConductorParams>(r);
  EXPECT_EQ(p.color_texture->colorspace, TextureColorspace::kLinear);
  EXPECT_EQ(p.color, Spectrum(0.5f));
  EXPECT_EQ(p.roughness_texture->colorspace, TextureColorspace::kLinear);
  EXPECT_EQ(p.roughness_texture->channel, 2);
  EXPECT_EQ(p.roughness, 0.25f);
}

TEST_F(Textures, EveryOptionIsRead) {
  const LoadResult r =
      load_material({{"type", "plastic"},
                     {"color",
                      {{"texture", "wood.png"},
                       {"colorspace", "linear"},
                       {"scale", {0.8, 0.6, 0.4}},
                       {"wrap", "clamp"},
                       {"filter", "nearest"}}},
                     {"normal_map", {{"texture", "normal.png"}, {"filter", "nearest"}}}});
  EXPECT_LOADS(r);
  const auto& p = material0<PlasticParams>(r);
  EXPECT_EQ(p.color, Spectrum(0.8f, 0.6f, 0.4f));
  EXPECT_EQ(p.color_texture->colorspace, TextureColorspace::kLinear);
  EXPECT_EQ(p.color_texture->wrap, TextureWrap::kClamp);
  EXPECT_EQ(p.color_texture->filter, TextureFilter::kNearest);
  ASSERT_TRUE(p.normal_map);
  EXPECT_EQ(p.normal_map->colorspace, TextureColorspace::kLinear);
  EXPECT_EQ(p.normal_map->filter, TextureFilter::kNearest);
}

TEST_F(Textures, NormalMapAsAFileName) {
  const LoadResult r = load_material({{"type", "dielectric"}, {"normal_map", "normal.png"}});
  EXPECT_LOADS(r);
  const auto& p = material0<DielectricParams>(r);
  ASSERT_TRUE(p.normal_map);
  EXPECT_EQ(p.normal_map->path, canonical("normal.png"));
  EXPECT_EQ(p.normal_map->colorspace, TextureColorspace::kLinear);
}

TEST_F(Textures, EmissionTexture) {
  Json scene = base_scene();
  scene["objects"][0]["emission"] = {{"texture", "wood.png"}, {"scale", 5}};
  const LoadResult r = load_with_assets(scene);
  EXPECT_LOADS(r);
  const ObjectDesc& o = r.request->scene.objects.at(0);
  EXPECT_EQ(o.emission, Spectrum(5.f));
  ASSERT_TRUE(o.emission_texture);
  EXPECT_EQ(o.emission_texture->colorspace, TextureColorspace::kSrgb);
  // Radiance may exceed 1, never go below 0.
  scene["objects"][0]["emission"]["scale"] = -1;
  EXPECT_ERROR(load_with_assets(scene), "/objects/0/emission/scale", ">= 0");
}

TEST_F(Textures, RefusalsNameTheField) {
  const std::string m = "/materials/white";
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", {{"texture", "nope.png"}}}}),
               m + "/color/texture", "no such file");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", {{"texture", "/etc/passwd"}}}}),
               m + "/color/texture", "relative");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", {{"texture", "../x.png"}}}}),
               m + "/color/texture", "'..'");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", {{"scale", 0.5}}}}),
               m + "/color/texture", "missing");
  EXPECT_ERROR(load_material(
                   {{"type", "diffuse"}, {"color", {{"texture", "wood.png"}, {"wrap", "mirror"}}}}),
               m + "/color/wrap", "expected \"repeat\" or \"clamp\"");
  EXPECT_ERROR(load_material({{"type", "diffuse"},
                              {"color", {{"texture", "wood.png"}, {"filter", "cubic"}}}}),
               m + "/color/filter", "\"bilinear\" or \"nearest\"");
  EXPECT_ERROR(load_material({{"type", "diffuse"},
                              {"color", {{"texture", "wood.png"}, {"colorspace", "srgbb"}}}}),
               m + "/color/colorspace", "did you mean 'srgb'");
  EXPECT_ERROR(
      load_material({{"type", "diffuse"}, {"color", {{"texture", "wood.png"}, {"scale", 1.5}}}}),
      m + "/color/scale", "[0, 1]");
  EXPECT_ERROR(
      load_material({{"type", "diffuse"}, {"color", {{"texture", "wood.png"}, {"channel", 1}}}}),
      m + "/color/channel", "single-value");
  EXPECT_ERROR(load_material(
                   {{"type", "diffuse"}, {"color", {{"texture", "wood.png"}, {"wrapp", "clamp"}}}}),
               m + "/color/wrapp", "wrap");
  EXPECT_ERROR(load_material({{"type", "conductor"},
                              {"roughness", {{"texture", "grey.png"}, {"channel", 1}}}}),
               m + "/roughness/channel", "1 channel(s)");
  EXPECT_ERROR(load_material({{"type", "conductor"},
                              {"roughness", {{"texture", "grey.png"}, {"channel", 4}}}}),
               m + "/roughness/channel", "[0, 3]");
  EXPECT_ERROR(load_material({{"type", "plastic"}, {"roughness", {{"texture", "grey.png"}}}}),
               m + "/roughness", "cannot be a texture");
  EXPECT_ERROR(load_material({{"type", "diffuse"},
                              {"normal_map", {{"texture", "normal.png"}, {"colorspace", "srgb"}}}}),
               m + "/normal_map/colorspace", "normal map");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"normal_map", "nope.png"}}), m + "/normal_map",
               "no such file");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"normal_map", 3}}), m + "/normal_map",
               "file name");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", "wood.png"}}), m + "/color",
               "must be an array of 3 numbers (got a string)");
  EXPECT_ERROR(load_material({{"type", "conductor"}, {"roughness", "wood.png"}}), m + "/roughness",
               "must be a number (got a string)");
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", {{"texture", 5}}}}),
               m + "/color/texture", "string");
}

TEST_F(Textures, NotAnImageIsRefused) {
  std::ofstream(dir_.file("notes.png")) << "this is not a png";
  EXPECT_ERROR(load_material({{"type", "diffuse"}, {"color", {{"texture", "notes.png"}}}}),
               "/materials/white/color/texture", "'notes.png': cannot read the image");
}

TEST_F(Textures, InlineScenesWithoutAFolderCannotNameTextures) {
  Json scene = base_scene();
  scene["materials"]["white"] = {{"type", "diffuse"}, {"color", {{"texture", "wood.png"}}}};
  EXPECT_ERROR(load_scene(scene.dump()), "/materials/white/color/texture", "no asset folder");
}

TEST_F(Textures, HeaderClaimingTenGigapixelsIsRefusedBeforeDecoding) {
  // A valid PNG signature and header for 100000 x 100000 RGB, then almost no data.
  std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\x01\x86\xa0\0\x01\x86\xa0\x08\x02\0\0\0", 29);
  // CRC of "IHDR" + the 13 header bytes, then an empty IEND-terminated stream.
  uint32_t c = 0xffffffffu;
  for (size_t i = 12; i < 29; ++i) {
    c ^= uint8_t(png[i]);
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
  }
  c ^= 0xffffffffu;
  png += std::string{char(c >> 24), char(c >> 16), char(c >> 8), char(c)};
  png += std::string("\0\0\0\x09IDAT\x78\x9c\x63\0\0\0\x01\0\x01\x11\x22\x33\x44", 21);
  std::ofstream(dir_.file("huge.png"), std::ios::binary) << png;
  const auto start = std::chrono::steady_clock::now();
  const LoadResult r = load_material({{"type", "diffuse"}, {"color", {{"texture", "huge.png"}}}});
  EXPECT_ERROR(r, "/materials/white/color/texture", "100000 x 100000 = 10000000000 pixels");
  EXPECT_ERROR(r, "/materials/white/color/texture", "(max_texture_pixels)");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST_F(Textures, PixelLimitAtTheLimitAndOneBelow) {
  const Json material = {{"type", "diffuse"}, {"color", {{"texture", "wood.png"}}}};  // 4 x 4
  Limits limits;
  limits.max_texture_pixels = 16;
  EXPECT_LOADS(load_material(material, limits));
  limits.max_texture_pixels = 15;
  EXPECT_ERROR(load_material(material, limits), "/materials/white/color/texture",
               "16 pixels, more than the limit of 15 (max_texture_pixels)");
}

TEST_F(Textures, MemoryLimitCountsEachDecodedImageOnceAtTheLimitAndOneBelow) {
  // wood.png: 4 x 4 x 3 bytes = 48 per colorspace; grey.png 4 x 4 x 1 = 16; hdr.exr 2 x 2 x 3
  // floats = 48.
  Json scene = base_scene();
  scene["materials"]["white"] = {{"type", "diffuse"}, {"color", {{"texture", "wood.png"}}}};
  scene["materials"]["again"] = {{"type", "plastic"},
                                 {"color", {{"texture", "wood.png"}}}};  // shared
  scene["materials"]["raw"] = {
      {"type", "diffuse"},
      {"color", {{"texture", "wood.png"}, {"colorspace", "linear"}}}};  // a second copy
  scene["materials"]["rough"] = {{"type", "conductor"}, {"roughness", {{"texture", "grey.png"}}}};
  for (const char* name : {"again", "raw", "rough"})
    scene["objects"].push_back(
        {{"type", "sphere"}, {"center", {3, 0, 0}}, {"radius", 1}, {"material", name}});
  Limits limits;
  limits.max_texture_bytes = 48 + 48 + 16;
  const LoadResult ok = load_with_assets(scene, limits);
  EXPECT_LOADS(ok);
  EXPECT_EQ(ok.request->scene.texture_limits.max_bytes, 112);
  limits.max_texture_bytes = 111;
  // Materials are read in name order: again, raw, rough, white; the last image to fit is grey.
  EXPECT_ERROR(load_with_assets(scene, limits), "/materials/rough/roughness/texture",
               "more than the limit of 111 bytes (max_texture_bytes)");
  // Float images count 4 bytes per channel.
  Json hdr = base_scene();
  hdr["materials"]["white"] = {{"type", "diffuse"}, {"color", {{"texture", "hdr.exr"}}}};
  limits.max_texture_bytes = 48;
  EXPECT_LOADS(load_with_assets(hdr, limits));
  limits.max_texture_bytes = 47;
  EXPECT_ERROR(load_with_assets(hdr, limits), "/materials/white/color/texture", "48 bytes");
}

TEST_F(Textures, ATexturedSceneBuildsAndRenders) {
  Json scene = base_scene();
  scene["materials"]["white"] = {
      {"type", "plastic"}, {"color", {{"texture", "wood.png"}}}, {"normal_map", "normal.png"}};
  scene["objects"][0]["emission"] = {{"texture", "hdr.exr"}};
  const LoadResult r = load_with_assets(scene);
  EXPECT_LOADS(r);
  const auto built = Scene::build(r.request->scene);
  RenderSettings s = r.request->settings;
  s.width = s.height = 8;
  s.spp = 4;
  const RenderResult out = render(*built, s);
  EXPECT_EQ(out.stats.nonfinite_samples, 0u);
  // The emitter's texture is 2 everywhere: the sphere, seen head on, shows 2.
  EXPECT_NEAR(out.image.pixel(4, 4)[0], 2.f, 1e-4f);
}

TEST_F(Textures, AFileChangedAfterLoadingFailsTheBuildNotTheProcess) {
  Json scene = base_scene();
  scene["materials"]["white"] = {{"type", "diffuse"}, {"color", {{"texture", "wood.png"}}}};
  const LoadResult r = load_with_assets(scene);
  EXPECT_LOADS(r);
  std::ofstream(dir_.file("wood.png"), std::ios::trunc) << "replaced";
  EXPECT_THROW(Scene::build(r.request->scene), SceneBuildError);
}

}  // namespace
}  // namespace penumbra::test
