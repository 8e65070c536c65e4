// A frame split into windows (render.window), rendered apart and merged, against the render of
// the whole frame: bit for bit with uniform sampling, unbiased with adaptive sampling; and the
// errors of bad windows and bad merges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "api/scene_loader.h"
#include "app_test_util.h"
#include "renderer/io/exr_window_file.h"
#include "renderer/render/render.h"
#include "renderer/render/window_merge.h"
#include "split_frame_test_util.h"

namespace penumbra::test {
namespace {

// Three windows tiling the 40x30 frame, none aligned to the render's 16-pixel tiles.
const PixelWindow kSplit[3] = {{0, 0, 40, 11}, {0, 11, 23, 30}, {23, 11, 40, 30}};

RenderResult render_scene(const nlohmann::json& scene, std::optional<PixelWindow> window) {
  SceneFolder folder;
  write_split_frame_scene(folder, scene);
  api::LoadResult loaded = api::load_scene_file(folder.file("scene.json"));
  EXPECT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors[0].to_string());
  if (!loaded.ok()) return {};
  RenderSettings settings = loaded.request->settings;
  settings.window = window;
  return render(*Scene::build(loaded.request->scene), settings);
}

MergedImage render_split(const nlohmann::json& scene) {
  std::vector<WindowPart> parts;
  for (const PixelWindow& w : kSplit) {
    RenderResult r = render_scene(scene, w);
    EXPECT_EQ(r.window, w);
    parts.push_back({"part", w, std::move(r.image), std::move(r.layers)});
  }
  return merge_windows(parts, 40, 30);
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(WindowMerge, ThreeWindowsEqualTheWholeFrameBitForBit) {
  nlohmann::json scene = split_frame_scene();
  scene["render"]["outputs"] = {"albedo", "normal", "depth"};
  const RenderResult whole = render_scene(scene, std::nullopt);
  const MergedImage merged = render_split(scene);
  EXPECT_TRUE(same_bits(merged.image.rgb, whole.image.rgb));
  ASSERT_EQ(merged.layers.size(), 3u);
  for (size_t l = 0; l < 3; ++l) {
    EXPECT_EQ(merged.layers[l].name, whole.layers[l].name);
    EXPECT_TRUE(same_bits(merged.layers[l].data, whole.layers[l].data)) << merged.layers[l].name;
  }
}

TEST(WindowMerge, WindowStatisticsCountOnlyItsPixels) {
  const RenderResult r = render_scene(split_frame_scene(), PixelWindow{3, 4, 13, 9});
  EXPECT_EQ(r.image.width, 10);
  EXPECT_EQ(r.image.height, 5);
  EXPECT_EQ(r.variance.width, 10);
  EXPECT_EQ(r.stats.camera_samples, 10u * 5u * 16u);
  EXPECT_EQ(r.stats.spp_min, 16);
  EXPECT_EQ(r.stats.spp_max, 16);
}

// Adaptive sampling decides within each window (renderer/render/render.cpp), so the split
// frame's pixels are other samples of the same estimator. Unbiased: the difference between the
// split and the whole frame's mean radiance is within the noise their variances predict.
TEST(WindowMerge, AdaptiveSplitIsUnbiased) {
  nlohmann::json scene = split_frame_scene();
  scene["render"]["spp"] = 256;
  scene["render"]["noise_threshold"] = 0.05;
  const RenderResult whole = render_scene(scene, std::nullopt);
  std::vector<WindowPart> parts;
  Image variance(40, 30);
  for (const PixelWindow& w : kSplit) {
    RenderResult r = render_scene(scene, w);
    for (int y = 0; y < w.height(); ++y)
      for (int x = 0; x < w.width(); ++x)
        for (int c = 0; c < 3; ++c) variance.pixel(w.x0 + x, w.y0 + y)[c] = r.variance.pixel(x, y)[c];
    parts.push_back({"part", w, std::move(r.image), {}});
  }
  const MergedImage split = merge_windows(parts, 40, 30);
  for (int c = 0; c < 3; ++c) {
    double diff = 0, var = 0;
    for (size_t i = 0; i < size_t(40 * 30); ++i) {
      diff += double(split.image.rgb[3 * i + c]) - whole.image.rgb[3 * i + c];
      var += double(variance.rgb[3 * i + c]) + whole.variance.rgb[3 * i + c];
    }
    // Pixel estimates are independent across pixels: the sum's variance is the sum of theirs.
    EXPECT_LT(std::abs(diff), 4.0 * std::sqrt(var)) << "channel " << c;
    EXPECT_GT(var, 0.0);
  }
}

WindowPart blank_part(const char* name, PixelWindow w) {
  return {name, w, Image(w.width(), w.height()), {}};
}

TEST(WindowMerge, OverlappingWindowsAreRejected) {
  try {
    merge_windows({blank_part("a.exr", {0, 0, 10, 6}), blank_part("b.exr", {0, 5, 10, 10})}, 10, 10);
    FAIL() << "merged overlapping windows";
  } catch (const WindowMergeError& e) {
    EXPECT_NE(std::string(e.what()).find("b.exr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("overlaps a.exr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(0, 5)"), std::string::npos) << e.what();
  }
}

TEST(WindowMerge, MissingPixelsAreRejected) {
  try {
    merge_windows({blank_part("a.exr", {0, 0, 10, 4}), blank_part("b.exr", {0, 5, 10, 10})}, 10, 10);
    FAIL() << "merged windows with a hole";
  } catch (const WindowMergeError& e) {
    EXPECT_NE(std::string(e.what()).find("10 pixels are in no window"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[0, 4, 10, 5)"), std::string::npos) << e.what();
  }
}

TEST(WindowMerge, WindowsOutsideTheImageOrWithOtherLayersAreRejected) {
  EXPECT_THROW(merge_windows({blank_part("a.exr", {0, 0, 11, 10})}, 10, 10), WindowMergeError);
  WindowPart with_layer = blank_part("b.exr", {0, 5, 10, 10});
  with_layer.layers.push_back({"depth", ImageLayer::Kind::kDepth, 1, std::vector<float>(50, 1.f)});
  EXPECT_THROW(merge_windows({blank_part("a.exr", {0, 0, 10, 5}), with_layer}, 10, 10), WindowMergeError);
  WindowPart wrong_size = blank_part("c.exr", {0, 0, 10, 10});
  wrong_size.image = Image(9, 10);
  EXPECT_THROW(merge_windows({wrong_size}, 10, 10), WindowMergeError);
  EXPECT_THROW(merge_windows({}, 10, 10), WindowMergeError);
}

// The command line: three `render --window` EXRs merged by `penumbra merge` equal `render`.
TEST(WindowMergeCommand, MergedPartsEqualTheWholeRender) {
  SceneFolder folder;
  write_split_frame_scene(folder, split_frame_scene());
  ASSERT_EQ(run_penumbra(folder, "render scene.json -q --aov depth -o whole.exr").exit_code, 0);
  std::string parts;
  for (int i = 0; i < 3; ++i) {
    const PixelWindow& w = kSplit[i];
    const std::string name = "part" + std::to_string(i) + ".exr";
    const CommandResult r = run_penumbra(
        folder, "render scene.json -q --aov depth -o " + name + " --window " + std::to_string(w.x0) + "," +
                    std::to_string(w.y0) + "," + std::to_string(w.x1) + "," + std::to_string(w.y1));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const ExrWindowFile part = read_exr_window(folder.file(name));
    EXPECT_EQ(part.display, (PixelWindow{0, 0, 40, 30}));
    EXPECT_EQ(part.part.window, w);
    parts += " " + name;
  }
  const CommandResult merged = run_penumbra(folder, "merge" + parts + " -o merged.exr");
  ASSERT_EQ(merged.exit_code, 0) << merged.output;
  const ExrWindowFile a = read_exr_window(folder.file("whole.exr"));
  const ExrWindowFile b = read_exr_window(folder.file("merged.exr"));
  EXPECT_EQ(b.part.window, (PixelWindow{0, 0, 40, 30}));
  EXPECT_TRUE(same_bits(a.part.image.rgb, b.part.image.rgb));
  ASSERT_EQ(b.part.layers.size(), 1u);
  EXPECT_TRUE(same_bits(a.part.layers[0].data, b.part.layers[0].data));

  // A PNG of a window holds the window's pixels.
  ASSERT_EQ(run_penumbra(folder, "render scene.json -q -o part.png --window 2,3,12,8").exit_code, 0);
  const Image png = read_image_file(folder.file("part.png"));
  EXPECT_EQ(png.width, 10);
  EXPECT_EQ(png.height, 5);
}

TEST(WindowMergeCommand, OverlapsAndHolesAreErrors) {
  SceneFolder folder;
  write_split_frame_scene(folder, split_frame_scene());
  ASSERT_EQ(run_penumbra(folder, "render scene.json -q -o a.exr --window 0,0,40,16").exit_code, 0);
  ASSERT_EQ(run_penumbra(folder, "render scene.json -q -o b.exr --window 0,15,40,30").exit_code, 0);
  ASSERT_EQ(run_penumbra(folder, "render scene.json -q -o c.exr --window 0,17,40,30").exit_code, 0);
  const CommandResult overlap = run_penumbra(folder, "merge a.exr b.exr -o m.exr");
  EXPECT_EQ(overlap.exit_code, 1);
  EXPECT_NE(overlap.output.find("overlaps"), std::string::npos) << overlap.output;
  EXPECT_NE(overlap.output.find("(0, 15)"), std::string::npos) << overlap.output;
  const CommandResult hole = run_penumbra(folder, "merge a.exr c.exr -o m.exr");
  EXPECT_EQ(hole.exit_code, 1);
  EXPECT_NE(hole.output.find("40 pixels are in no window"), std::string::npos) << hole.output;
  EXPECT_FALSE(std::filesystem::exists(folder.file("m.exr")));
}

TEST(WindowMergeCommand, BadWindowsNameTheFlagAndPointer) {
  SceneFolder folder;
  write_split_frame_scene(folder, split_frame_scene());
  struct Case {
    const char* window;
    const char* expected;
  } cases[] = {
      {"0,0,41,10", "--window (/render/window/2): must be in [0, 40]"},
      {"0,-1,10,10", "--window (/render/window/1): must be in [0, 30]"},
      {"5,0,5,10", "--window (/render/window): must be [x0, y0, x1, y1] with x0 < x1"},
      {"10,0,5,10", "--window (/render/window): must be [x0, y0, x1, y1] with x0 < x1"},
      {"0,0,10", "--window (/render/window): must be an array of 4 integers"},
      {"0,0,a,10", "--window (/render/window/2): must be an integer"},
  };
  for (const Case& c : cases) {
    const CommandResult r = run_penumbra(folder, std::string("render scene.json -q -o x.exr --window ") + c.window);
    EXPECT_EQ(r.exit_code, 1) << c.window;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.window << ": " << r.output;
  }
  const CommandResult denoise =
      run_penumbra(folder, "render scene.json -q -o x.exr --window 0,0,10,10 --denoise");
  EXPECT_EQ(denoise.exit_code, 1);
  EXPECT_NE(denoise.output.find("--denoise (/render/denoise): a window of the image cannot be denoised alone"),
            std::string::npos)
      << denoise.output;
}

}  // namespace
}  // namespace penumbra::test
