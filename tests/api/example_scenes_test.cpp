// Every scene shipped in scenes/ loads without errors or warnings.
#include <filesystem>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(ExampleScenes, AllLoadCleanly) {
  const std::filesystem::path dir = std::filesystem::path(PENUMBRA_SOURCE_DIR) / "scenes";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    ++count;
    const LoadResult r = load_scene_file(entry.path().string());
    EXPECT_TRUE(r.ok()) << entry.path() << "\n" << describe(r.errors);
    EXPECT_TRUE(r.warnings.empty()) << entry.path() << "\n" << describe(r.warnings);
    if (!r.ok()) continue;
    // "Renders in a few seconds": keep the examples small.
    const RenderSettings& s = r.request->settings;
    EXPECT_LE(s.width, 256) << entry.path();
    EXPECT_LE(s.height, 256) << entry.path();
    EXPECT_LE(s.spp, 64) << entry.path();
  }
  for (const char* required : {"cornell_box.json", "glass.json", "metals.json",
                               "depth_of_field.json", "motion_blur.json", "mesh.json", "textures.json",
                               "instances.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / required)) << required;
  EXPECT_GE(count, 7);
}

TEST(ExampleScenes, MissingFileIsAnErrorOnTheRoot) {
  const LoadResult r = load_scene_file("/nonexistent/scene.json");
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(has(r.errors, "", "cannot read file")) << describe(r.errors);
  const LoadResult dir = load_scene_file(PENUMBRA_SOURCE_DIR);
  EXPECT_TRUE(has(dir.errors, "", "cannot read file")) << describe(dir.errors);
}

}  // namespace
}  // namespace penumbra::test
