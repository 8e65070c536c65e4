// `penumbra render` flags are checked with the scene, by api's code and limits, and a bad one
// stops the command with the JSON field's message naming the flag (api/render_overrides.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/app/app_test_util.h"

namespace penumbra::test {
namespace {

// `penumbra render scene.json FLAGS -o out.png` exits 1 with exactly `output`, writing no image.
void expect_render_refused(const std::string& flags, const std::string& output) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "render scene.json " + flags + " -o out.png");
  EXPECT_EQ(r.exit_code, 1) << flags;
  EXPECT_EQ(r.output, output) << flags;
  EXPECT_FALSE(std::filesystem::exists(folder.file("out.png")));
}

// `penumbra render scene.json FLAGS -q -o out.exr` writes the image; returns what it printed.
std::string expect_rendered(const std::string& flags) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "render scene.json " + flags + " -q -o out.exr");
  EXPECT_EQ(r.exit_code, 0) << flags << "\n" << r.output;
  EXPECT_TRUE(std::filesystem::exists(folder.file("out.exr"))) << flags;
  return r.output;
}

TEST(RenderFlags, SizePastTheLimitsFails) {
  expect_render_refused("--width 65536 --height 65536",
                        "scene.json: --width (/render/width): must be <= 8192 (max_width)\n"
                        "scene.json: --height (/render/height): must be <= 8192 (max_height)\n");
}

TEST(RenderFlags, SizeAtThePixelLimitRenders) {
  // 8192 x 2048 = max_pixels; the time limit keeps the render itself short.
  const std::string output = expect_rendered("--width 8192 --height 2048 --spp 1 --time-limit 0.01");
  EXPECT_NE(output.find("8192x2048"), std::string::npos) << output;
  expect_render_refused("--width 8192 --height 2049",
                        "scene.json: /render: width x height = 16785408 pixels exceeds the limit "
                        "of 16777216 (max_pixels)\n");
}

TEST(RenderFlags, BadValuesGetTheFieldsMessages) {
  // --threads is read before the scene's fields.
  expect_render_refused(
      "--width abc --spp=2.5 --threads 4097 --integrator pth",
      "scene.json: --threads: must be in [0, 4096]\n"
      "scene.json: --width (/render/width): must be an integer (got a string)\n"
      "scene.json: --spp (/render/spp): must be an integer\n"
      "scene.json: --integrator (/render/integrator): unknown integrator 'pth' (did you mean "
      "'path'?); expected \"path\" or \"distributed\"\n");
}

TEST(RenderFlags, GoodValuesRender) {
  expect_rendered("--width 8 --height 4 --spp 1 --threads 4096 --seed 3 --max-depth -1");
  expect_rendered("--width=1 --height=1 --spp=1 --threads=0 --integrator=distributed");
}

TEST(RenderFlags, BenchChecksTheSameWay) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "bench scene.json --width 0 --repeat 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.output, "scene.json: --width (/render/width): must be >= 1\n");
}

TEST(RenderFlags, ValidateTakesNoRenderFlags) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "validate scene.json --width 64");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("unknown option '--width'"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace penumbra::test
