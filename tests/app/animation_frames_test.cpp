// Animations as frames: frame i renders exactly the scene with the shutter [i / fps,
// (i + shutter) / fps] written by hand; frames differ where objects move; `penumbra render
// --frame N` and `--frames` with a # pattern.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "api/animation_parser.h"
#include "api/scene_loader.h"
#include "app_test_util.h"
#include "renderer/io/exr_window_file.h"
#include "renderer/render/render.h"
#include "split_frame_test_util.h"

namespace penumbra::test {
namespace {

nlohmann::json animated_scene(int first, int last) {
  nlohmann::json s = split_frame_scene();
  s["camera"].erase("shutter");
  s["animation"] = {{"frames", {first, last}}, {"fps", 24}, {"shutter", 0.5}};
  return s;
}

Image render_frame(const nlohmann::json& scene, std::optional<int64_t> frame) {
  SceneFolder folder;
  write_split_frame_scene(folder, scene);
  api::LoadResult loaded = api::load_scene_file(folder.file("scene.json"));
  EXPECT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors[0].to_string());
  if (!loaded.ok()) return {};
  if (frame) {
    api::Diagnostics diag;
    EXPECT_TRUE(api::select_frame(*loaded.request, *frame, diag));
  }
  return render(*Scene::build(loaded.request->scene), loaded.request->settings).image;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(AnimationFrames, FrameEqualsItsShutterWrittenByHand) {
  const Image frame17 = render_frame(animated_scene(0, 23), 17);
  nlohmann::json by_hand = split_frame_scene();
  // The numbers as JSON carries them: doubles, as a user or a script would write 17 / 24.
  by_hand["camera"]["shutter"] = {17.0 / 24.0, 17.5 / 24.0};
  const Image hand = render_frame(by_hand, std::nullopt);
  EXPECT_TRUE(same_bits(frame17.rgb, hand.rgb));

  const Image frame16 = render_frame(animated_scene(0, 23), 16);
  EXPECT_FALSE(same_bits(frame16.rgb, frame17.rgb)) << "the moving sphere did not move";
  // The first frame is what a consumer that knows nothing of frames renders.
  EXPECT_TRUE(same_bits(render_frame(animated_scene(5, 9), std::nullopt).rgb,
                        render_frame(animated_scene(5, 9), 5).rgb));
}

TEST(AnimationFrames, FramesWriteOneFilePerFrame) {
  SceneFolder folder;
  write_split_frame_scene(folder, animated_scene(3, 5));
  const CommandResult all = run_penumbra(folder, "render scene.json -q --frames -o out_####.exr");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  for (int f = 3; f <= 5; ++f) EXPECT_TRUE(std::filesystem::exists(folder.file("out_000" + std::to_string(f) + ".exr")));
  EXPECT_FALSE(std::filesystem::exists(folder.file("out_0006.exr")));
  ASSERT_EQ(run_penumbra(folder, "render scene.json -q --frame 4 -o single.exr").exit_code, 0);
  const ExrWindowFile a = read_exr_window(folder.file("out_0004.exr"));
  const ExrWindowFile b = read_exr_window(folder.file("single.exr"));
  EXPECT_TRUE(same_bits(a.part.image.rgb, b.part.image.rgb));
  const ExrWindowFile c = read_exr_window(folder.file("out_0003.exr"));
  EXPECT_FALSE(same_bits(a.part.image.rgb, c.part.image.rgb));
  bool has_frame_attribute = false;
  for (const auto& [k, v] : a.metadata) has_frame_attribute |= k == "penumbra:frame" && v == "4";
  EXPECT_TRUE(has_frame_attribute);
}

TEST(AnimationFrames, FrameFlagErrors) {
  SceneFolder folder;
  write_split_frame_scene(folder, animated_scene(3, 5));
  const CommandResult outside = run_penumbra(folder, "render scene.json -q --frame 9 -o x.exr");
  EXPECT_EQ(outside.exit_code, 1);
  EXPECT_NE(outside.output.find("--frame (/animation/frames): frame 9 is outside the animation's frames [3, 5]"),
            std::string::npos)
      << outside.output;
  const CommandResult no_pattern = run_penumbra(folder, "render scene.json -q --frames -o x.exr");
  EXPECT_EQ(no_pattern.exit_code, 2);
  EXPECT_NE(no_pattern.output.find("# pattern"), std::string::npos) << no_pattern.output;
  const CommandResult both = run_penumbra(folder, "render scene.json -q --frames --frame 4 -o x_#.exr");
  EXPECT_EQ(both.exit_code, 2);

  SceneFolder still;
  write_split_frame_scene(still, split_frame_scene());
  const CommandResult none = run_penumbra(still, "render scene.json -q --frame 1 -o x.exr");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.output.find("no \"animation\""), std::string::npos) << none.output;
}

TEST(AnimationFrames, InfoShowsTheAnimationAndTheWindow) {
  SceneFolder folder;
  nlohmann::json scene = animated_scene(3, 50);
  scene["render"]["window"] = {2, 3, 12, 9};
  write_split_frame_scene(folder, scene);
  const CommandResult r = run_penumbra(folder, "info scene.json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("animation   frames 3 to 50 (48), 24 fps, shutter 0.5 of a frame"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("window      [2, 3, 12, 9): 10 x 6 pixels"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace penumbra::test
