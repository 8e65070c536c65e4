// "environment": the constant form and the image form ("map", "scale", "rotate" | "matrix"), the
// image read through the scene's asset folder, and every refusal named by its field.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "api/embedded_documents.h"
#include "renderer/io/image_io.h"
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class EnvironmentField : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_.root = fs::temp_directory_path() / ("penumbra_environment_" + std::to_string(::getpid()));
    fs::remove_all(folder_.root);
    fs::create_directories(folder_.root / "maps");
    // 4 x 2 texels: texel (x, y) = (x, y, 1).
    Image sky(4, 2);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) {
        sky.pixel(x, y)[0] = float(x);
        sky.pixel(x, y)[1] = float(y);
        sky.pixel(x, y)[2] = 1.f;
      }
    write_image_file((folder_.root / "maps" / "sky.exr").string(), sky);
    write_image_file((folder_.root / "black.exr").string(), Image(2, 2));
  }
  void TearDown() override { fs::remove_all(folder_.root); }

  LoadResult load_with(const Json& environment) {
    Json scene = base_scene();
    scene["environment"] = environment;
    return load_scene(scene.dump(), {}, {}, folder_);
  }
  void write_file(const std::string& name, const std::string& bytes) {
    std::ofstream(folder_.root / name, std::ios::binary) << bytes;
  }

  AssetFolder folder_;
};

TEST_F(EnvironmentField, MapIsReadWithDefaults) {
  const LoadResult r = load_with({{"map", "maps/sky.exr"}});
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const SceneInput& in = r.request->scene;
  EXPECT_EQ(in.environment, Spectrum(0.f));
  ASSERT_TRUE(in.environment_map.has_value());
  const EnvironmentMapDesc& m = *in.environment_map;
  EXPECT_EQ(m.width, 4);
  EXPECT_EQ(m.height, 2);
  ASSERT_TRUE(m.rgb);
  ASSERT_EQ(m.rgb->size(), 4u * 2u * 3u);
  // Row 0 of the file is the top row: texel (3, 1) = (3, 1, 1).
  EXPECT_EQ((*m.rgb)[(1 * 4 + 3) * 3 + 0], 3.f);
  EXPECT_EQ((*m.rgb)[(1 * 4 + 3) * 3 + 1], 1.f);
  EXPECT_EQ(m.scale, 1.f);
  EXPECT_EQ(m.to_world, glm::mat3(1.f));
  EXPECT_FALSE(m.uniform_sampling);
}

TEST_F(EnvironmentField, ScaleAndRotateAreApplied) {
  const LoadResult r = load_with(Json::parse(
      R"({"map": "maps/sky.exr", "scale": 2.5, "rotate": {"axis": [0, 1, 0], "degrees": 90}})"));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const EnvironmentMapDesc& m = *r.request->scene.environment_map;
  // The scale is applied to the texels (so the light can share them) and the map's is 1.
  EXPECT_EQ(m.scale, 1.f);
  EXPECT_EQ((*m.rgb)[(1 * 4 + 3) * 3 + 0], 3.f * 2.5f);
  EXPECT_EQ((*m.rgb)[(1 * 4 + 3) * 3 + 1], 1.f * 2.5f);
  // Right-handed about +y: the map's centre column (+z) faces +x.
  const vec3 z = m.to_world * vec3(0, 0, 1);
  EXPECT_NEAR(z.x, 1.f, 1e-6f);
  EXPECT_NEAR(z.z, 0.f, 1e-6f);
}

TEST_F(EnvironmentField, MatrixMustBeARotation) {
  // A rotation typed with 7 decimals comes out exactly orthogonal.
  const LoadResult ok = load_with(Json::parse(R"({"map": "maps/sky.exr", "matrix":
      [0.8660254, 0, 0.5, 0,  0, 1, 0, 0,  -0.5, 0, 0.8660254, 0,  0, 0, 0, 1]})"));
  ASSERT_TRUE(ok.ok()) << describe(ok.errors);
  const glm::mat3 m = ok.request->scene.environment_map->to_world;
  const glm::mat3 gram = glm::transpose(m) * m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(gram[c][r], c == r ? 1.f : 0.f, 1e-6f);
  const char* refused[] = {
      R"([1, 0, 0, 5,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1])",   // translation
      R"([2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  0, 0, 0, 1])",   // scale
      R"([1, 0.5, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1])"  // shear
  };
  for (const char* matrix : refused) {
    Json env = {{"map", "maps/sky.exr"}};
    env["matrix"] = Json::parse(matrix);
    EXPECT_ERROR(load_with(env), "/environment/matrix", "must be a rotation");
  }
  Json both = Json::parse(R"({"map": "maps/sky.exr", "rotate": {"axis": [0, 1, 0], "degrees": 9}})");
  both["matrix"] = Json::parse(refused[0]);
  EXPECT_ERROR(load_with(both), "/environment/rotate", "cannot be combined");
  EXPECT_ERROR(load_with(Json::parse(R"({"map": "maps/sky.exr", "rotate": {"axis": [0, 0, 0], "degrees": 9}})")),
               "/environment/rotate/axis", "nonzero");
}

TEST_F(EnvironmentField, ConstantAndImageFormsDoNotMix) {
  EXPECT_ERROR(load_with(Json::parse(R"({"map": "maps/sky.exr", "radiance": [1, 1, 1]})")),
               "/environment/radiance", "cannot be combined");
  EXPECT_ERROR(load_with(Json::parse(R"({"radiance": [1, 1, 1], "scale": 2})")),
               "/environment/scale", "applies only");
  EXPECT_ERROR(load_with(Json::parse(R"({"radiance": [1, 1, 1], "rotate": {"axis": [0, 1, 0], "degrees": 9}})")),
               "/environment/rotate", "applies only");
  EXPECT_ERROR(load_with(Json::parse(R"({"maps": "maps/sky.exr"})")), "/environment/maps", "did you mean");
}

TEST_F(EnvironmentField, ScaleRange) {
  EXPECT_ERROR(load_with(Json::parse(R"({"map": "maps/sky.exr", "scale": -1})")), "/environment/scale",
               "must be >= 0");
  // 3 (the brightest texel) x 1e30 would overflow the renderer's arithmetic.
  EXPECT_ERROR(load_with(Json::parse(R"({"map": "maps/sky.exr", "scale": 1e30})")), "/environment/scale",
               "brightest texel");
  EXPECT_ERROR(load_with(Json::parse(R"({"map": 7})")), "/environment/map", "must be a string");
}

TEST_F(EnvironmentField, PathsStayInTheSceneFolder) {
  EXPECT_ERROR(load_with({{"map", "maps/none.exr"}}), "/environment/map", "no such file");
  // Reported alongside the other fields' errors.
  const LoadResult both = load_with(Json::parse(R"({"map": "maps/none.exr", "scale": -1})"));
  EXPECT_ERROR(both, "/environment/map", "no such file");
  EXPECT_ERROR(both, "/environment/scale", "must be >= 0");
  EXPECT_ERROR(load_with({{"map", "../sky.exr"}}), "/environment/map", "'..'");
  EXPECT_ERROR(load_with({{"map", (folder_.root / "maps" / "sky.exr").string()}}), "/environment/map",
               "not absolute");
  // Inline JSON without a folder (e.g. a service request without assets) may name no file.
  Json scene = base_scene();
  scene["environment"] = {{"map", "maps/sky.exr"}};
  EXPECT_ERROR(load_scene(scene.dump()), "/environment/map", "no asset folder");
}

TEST_F(EnvironmentField, UnreadableAndOversizedImagesAreRefusedByName) {
  write_file("garbage.exr", "this is not an image");
  const LoadResult garbage = load_with({{"map", "garbage.exr"}});
  EXPECT_ERROR(garbage, "/environment/map", "'garbage.exr'");
  // The message names the file as typed, not where the folder lives.
  for (const Diagnostic& d : garbage.errors)
    EXPECT_EQ(d.message.find(folder_.root.string()), std::string::npos) << d.message;
  // A Radiance header claiming 100000 x 100000 pixels, and no pixels: refused on the header.
  write_file("huge.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n");
  EXPECT_ERROR(load_with({{"map", "huge.hdr"}}), "/environment/map", "per side");
  write_file("wide.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 60000 +X 60000\n");
  EXPECT_ERROR(load_with({{"map", "wide.hdr"}}), "/environment/map", "pixels; at most");
}

TEST_F(EnvironmentField, BlackMapWarns) {
  const LoadResult r = load_with({{"map", "black.exr"}});
  EXPECT_LOADS(r);
  EXPECT_TRUE(has(r.warnings, "/environment/map", "black")) << describe(r.warnings);
  Json scene = base_scene();
  scene["objects"][0].erase("emission");
  scene["environment"] = {{"map", "black.exr"}};
  const LoadResult unlit = load_scene(scene.dump(), {}, {}, folder_);
  EXPECT_TRUE(has(unlit.warnings, "", "the image will be black")) << describe(unlit.warnings);
  scene["environment"] = {{"map", "maps/sky.exr"}};
  const LoadResult lit = load_scene(scene.dump(), {}, {}, folder_);
  EXPECT_FALSE(has(lit.warnings, "", "the image will be black")) << describe(lit.warnings);
}

// 8-bit formats hold sRGB-encoded values: decoded to linear, as Mitsuba's Bitmap does.
TEST_F(EnvironmentField, IntegerImagesAreLinearised) {
  Image grey(2, 1);
  for (float& v : grey.rgb) v = 0.5f;
  write_image_file((folder_.root / "grey.png").string(), grey);  // stored as sRGB 188/255
  const LoadResult r = load_with({{"map", "grey.png"}});
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_NEAR((*r.request->scene.environment_map->rgb)[0], 0.5f, 0.005f);
}

// The texels are cleaned and scaled in blocks of 65536 values on all cores
// (renderer/core/row_blocks.h): a map of 300 x 80 texels is one full block and a shorter one.
// Values to clean and the brightest texel in the last, shorter block are found there too: the
// check on the brightest texel x scale sees it, and every value is clean(value) x scale.
TEST_F(EnvironmentField, EveryBlockOfTexelsIsCleanedScaledAndChecked) {
  const int w = 300, h = 80;
  Image sky(w, h);
  for (size_t i = 0; i < sky.rgb.size(); ++i) sky.rgb[i] = 0.25f + float(i % 37);
  const size_t last = sky.rgb.size() - 1;
  sky.rgb[10] = -2.f;
  sky.rgb[last - 1] = -1.f;
  sky.rgb[last - 2] = -0.f;
  sky.rgb[last] = 60000.f;  // the brightest, in the last block
  write_image_file((folder_.root / "blocks.exr").string(), sky);
  const LoadResult r = load_with(Json::parse(R"({"map": "blocks.exr", "scale": 0.5})"));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const std::vector<float>& rgb = *r.request->scene.environment_map->rgb;
  ASSERT_EQ(rgb.size(), sky.rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    const float expected = sky.rgb[i] > 0.f ? sky.rgb[i] * 0.5f : 0.f;
    ASSERT_EQ(rgb[i], expected) << i;
    ASSERT_FALSE(std::signbit(rgb[i])) << i;  // -0 is cleaned to +0
  }
  // 60000 x 2e25 is over the limit of 1e30; the other texels (at most 36.25) x 2e25 are not.
  EXPECT_ERROR(load_with(Json::parse(R"({"map": "blocks.exr", "scale": 2e25})")), "/environment/scale",
               "brightest texel");
}

TEST(EnvironmentSchema, DocumentsEveryField) {
  const std::string* text = embedded_document("scene.schema.json");
  ASSERT_NE(text, nullptr);
  const Json properties = Json::parse(*text)["properties"]["environment"]["properties"];
  for (const char* key : {"radiance", "map", "scale", "rotate", "matrix"}) {
    ASSERT_TRUE(properties.contains(key)) << key;
    EXPECT_TRUE(properties[key].contains("description")) << key;
  }
}

}  // namespace
}  // namespace penumbra::test
