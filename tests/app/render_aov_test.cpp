// `penumbra render --aov`: the output layers end to end through the binary: a multi-layer EXR
// (plain and Blender names, read back with OpenEXR), one PNG per layer beside a PNG, and the
// refusals of a layout that cannot be written.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "tests/app/app_test_util.h"
#include "tests/app/exr_test_util.h"

namespace penumbra::test {
namespace {

TEST(RenderAov, MultiLayerExrWithPlainNames) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "render scene.json --aov albedo,normal,depth -q -o out.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(exr_channels(folder.file("out.exr")),
            (std::set<std::string>{"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.X",
                                   "normal.Y", "normal.Z", "depth.Z"}));
  // The scene's sphere (radius 1, 5 from the camera) fills the centre: its front at depth 4,
  // its colour 0.8; the corners see nothing.
  const std::vector<float> depth = read_exr_channel(folder.file("out.exr"), "depth.Z");
  const std::vector<float> albedo = read_exr_channel(folder.file("out.exr"), "albedo.G");
  const size_t centre = size_t(6) * 16 + 8;
  EXPECT_NEAR(depth[centre], 4.f, 0.15f);  // a few degrees off the axis
  EXPECT_NEAR(albedo[centre], 0.8f, 1e-6f);
  EXPECT_EQ(depth[0], 1e10f);
  EXPECT_FALSE(std::filesystem::exists(folder.file("out.albedo.exr")));
}

TEST(RenderAov, BlenderLayoutAndSeparateFiles) {
  SceneFolder folder;
  CommandResult r = run_penumbra(folder, "render scene.json --aov depth --layout blender -q -o b.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(exr_channels(folder.file("b.exr")),
            (std::set<std::string>{"ViewLayer.Combined.R", "ViewLayer.Combined.G",
                                   "ViewLayer.Combined.B", "ViewLayer.Combined.A",
                                   "ViewLayer.Depth.Z"}));
  r = run_penumbra(folder, "render scene.json --aov albedo,normal,depth -q -o p.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"p.png", "p.albedo.png", "p.normal.png", "p.depth.png"})
    EXPECT_TRUE(std::filesystem::exists(folder.file(f))) << f;
  r = run_penumbra(folder, "render scene.json --aov normal --layout separate -q -o s.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(exr_channels(folder.file("s.exr")), (std::set<std::string>{"R", "G", "B"}));
  EXPECT_EQ(exr_channels(folder.file("s.normal.exr")), (std::set<std::string>{"X", "Y", "Z"}));
}

TEST(RenderAov, RefusedBeforeRendering) {
  SceneFolder folder;
  CommandResult r = run_penumbra(folder, "render scene.json --aov normal --layout blender -q -o x.png");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--layout blender writes a multi-layer EXR"), std::string::npos) << r.output;
  r = run_penumbra(folder, "render scene.json --layout nuke -q -o x.exr");
  EXPECT_EQ(r.exit_code, 2);
  r = run_penumbra(folder, "render scene.json --aov albedo,nrmal -q -o x.exr");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("--aov (/render/outputs/1): unknown output layer 'nrmal'"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(folder.file("x.exr")));
}

}  // namespace
}  // namespace penumbra::test
