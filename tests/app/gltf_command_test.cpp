// `penumbra render MODEL.glb` and `penumbra info MODEL.glb`: a glTF asset rendered directly,
// through its own camera (size from its aspect ratio) or a camera framing it, under its lights
// or a neutral environment.
#include <gtest/gtest.h>

#include <fstream>

#include "tests/app/app_test_util.h"
#include "tests/renderer/io/gltf_test_util.h"

namespace penumbra::test {
namespace {

void write(const SceneFolder& folder, const std::string& name, const std::vector<uint8_t>& bytes) {
  std::ofstream(folder.file(name), std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

GltfBuilder red_triangle() {
  GltfBuilder b;
  b.doc["materials"] = nlohmann::json::array(
      {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.1, 0.1, 1}}, {"metallicFactor", 0}}}}});
  b.node({{"mesh", b.triangle(0)}});
  return b;
}

TEST(GltfCommand, RendersAGlbWithOneCommand) {
  SceneFolder folder;
  write(folder, "model.glb", red_triangle().glb());
  const CommandResult r = run_penumbra(folder, "render model.glb -o out.png --spp 2 --width 40 --height 30");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(folder.file("out.png")));
  EXPECT_NE(r.output.find("40x30"), std::string::npos) << r.output;
}

TEST(GltfCommand, InfoDescribesTheAssetAndItsCamera) {
  SceneFolder folder;
  GltfBuilder b = red_triangle();
  b.doc["cameras"] = nlohmann::json::array(
      {{{"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.1}, {"aspectRatio", 2.0}}}}});
  b.node({{"camera", 0}, {"translation", {0, 0, 4}}});
  write(folder, "model.gltf", b.gltf_bytes());
  const CommandResult r = run_penumbra(folder, "info model.gltf");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("glTF asset, rendered at 800 x 400 pixels"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 mesh at 1 node -> 1 triangle"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("environment constant"), std::string::npos) << r.output;
}

TEST(GltfCommand, BadAssetsFailNamingTheFile) {
  SceneFolder folder;
  std::vector<uint8_t> glb = red_triangle().glb();
  glb.resize(40);
  write(folder, "cut.glb", glb);
  const CommandResult r = run_penumbra(folder, "render cut.glb -o out.png");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("'cut.glb': truncated GLB"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace penumbra::test
