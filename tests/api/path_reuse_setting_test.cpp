// render.path_reuse (api/scene_parser.cpp): the block side of path reuse, 1 (off) to 4, from the
// scene or the command line, and errors that name the field.
#include "api/render_overrides.h"
#include "tests/api/scene_test_util.h"

#include <vector>

namespace penumbra::test {
namespace {

TEST(PathReuseSetting, OffUnlessAskedAndTakenFromOneToFour) {
  Json scene = base_scene();
  LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(r.request->settings.path_reuse, 1);
  for (int n = 1; n <= 4; ++n) {
    scene["render"] = {{"path_reuse", n}};
    r = load(scene);
    ASSERT_TRUE(r.ok()) << describe(r.errors);
    EXPECT_EQ(r.request->settings.path_reuse, n);
  }
}

TEST(PathReuseSetting, ErrorsNameTheField) {
  Json scene = base_scene();
  scene["render"] = {{"path_reuse", 0}};
  EXPECT_ERROR(load(scene), "/render/path_reuse", "must be 1 (off) to 4");
  scene["render"] = {{"path_reuse", 5}};
  EXPECT_ERROR(load(scene), "/render/path_reuse", "must be 1 (off) to 4");
  scene["render"] = {{"path_reuse", 2.5}};
  EXPECT_ERROR(load(scene), "/render/path_reuse", "integer");
  scene["render"] = {{"path_reuse", "4"}};
  EXPECT_ERROR(load(scene), "/render/path_reuse", "integer");
}

TEST(PathReuseSetting, TheCommandLineFlagSetsIt) {
  const std::vector<RenderOverride> flag = {{"--path-reuse", "4"}};
  const LoadResult r = load_scene(base_scene().dump(), {}, flag);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(r.request->settings.path_reuse, 4);
  const std::vector<RenderOverride> bad = {{"--path-reuse", "9"}};
  EXPECT_FALSE(load_scene(base_scene().dump(), {}, bad).ok());
}

}  // namespace
}  // namespace penumbra::test
