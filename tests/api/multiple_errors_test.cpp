// All errors of a scene are reported in one pass, and their number is bounded.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(MultipleErrors, AreAllCollected) {
  const LoadResult r = load_scene(R"({
    "version": 1,
    "render": {"width": -1, "spp": 2.5},
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 0},
    "materials": {"gold": {"type": "conductor", "roughness": 2}},
    "objects": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 0, "material": "gold"},
      {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "silver"},
      {"type": "quad", "origin": [0, 0, 0], "u": [1, 0, 0], "v": [1, 0, 0], "material": "gold"}
    ]
  })");
  EXPECT_EQ(r.kind, LoadErrorKind::kInvalid);
  EXPECT_ERROR(r, "/render/width", "must be >= 1");
  EXPECT_ERROR(r, "/render/spp", "must be an integer");
  EXPECT_ERROR(r, "/camera/fov", "(0, 180)");
  EXPECT_ERROR(r, "/materials/gold/roughness", "[0, 1]");
  EXPECT_ERROR(r, "/objects/0/radius", "must be > 0");
  EXPECT_ERROR(r, "/objects/1/material", "unknown material 'silver'");
  EXPECT_ERROR(r, "/objects/2", "zero-area quad");
  EXPECT_EQ(r.errors.size(), 7u) << describe(r.errors);
}

TEST(MultipleErrors, AreCappedWithACountOfTheRest) {
  Json scene = base_scene();
  Json m = {{"type", "mesh"}, {"material", "white"}, {"positions", {0, 0, 0, 1, 0, 0, 0, 1, 0}}};
  m["indices"] = Json::array();
  for (int i = 0; i < 3000; ++i) m["indices"].push_back(7);
  scene["objects"].push_back(m);
  const LoadResult r = load(scene);
  ASSERT_EQ(r.errors.size(), 101u);
  EXPECT_EQ(r.errors.back().pointer, "");
  EXPECT_EQ(r.errors.back().message, "2900 more errors not shown");
}

TEST(MultipleErrors, ToStringUsesSlashForTheRoot) {
  EXPECT_EQ((Diagnostic{"", "bad"}).to_string(), "/: bad");
  EXPECT_EQ((Diagnostic{"/a/0", "bad"}).to_string(), "/a/0: bad");
}

}  // namespace
}  // namespace penumbra::test
