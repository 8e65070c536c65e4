// Every limit at its boundary: the limit passes, limit + 1 fails on the field's pointer with the
// limit's value in the message.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

Json sphere(int i) {
  return {{"type", "sphere"}, {"center", {i, 0, 0}}, {"radius", 0.5}, {"material", "white"}};
}

TEST(Limits, WidthHeightPixels) {
  Limits limits;
  limits.max_width = 100;
  limits.max_height = 80;
  limits.max_pixels = 100 * 60;
  Json scene = base_scene();
  scene["render"] = {{"width", 100}, {"height", 60}};
  EXPECT_LOADS(load(scene, limits));
  scene["render"] = {{"width", 101}, {"height", 10}};
  EXPECT_ERROR(load(scene, limits), "/render/width", "must be <= 100 (max_width)");
  scene["render"] = {{"width", 10}, {"height", 81}};
  EXPECT_ERROR(load(scene, limits), "/render/height", "must be <= 80 (max_height)");
  scene["render"] = {{"width", 100}, {"height", 61}};
  EXPECT_ERROR(load(scene, limits), "/render", "6100 pixels exceeds the limit of 6000 (max_pixels)");
}

TEST(Limits, DefaultPixelLimit) {
  Json scene = base_scene();
  scene["render"] = {{"width", 4096}, {"height", 4096}};
  EXPECT_LOADS(load(scene));
  scene["render"] = {{"width", 4097}, {"height", 4096}};
  EXPECT_ERROR(load(scene), "/render", "(max_pixels)");
}

TEST(Limits, SppDepthTime) {
  Limits limits;
  limits.max_spp = 16;
  limits.max_depth = 20;
  limits.max_time_limit = 60;
  Json scene = base_scene();
  scene["render"] = {{"spp", 16}, {"max_depth", 20}, {"rr_depth", 20}, {"time_limit", 60}};
  EXPECT_LOADS(load(scene, limits));
  scene["render"] = {{"spp", 17}, {"max_depth", 21}, {"rr_depth", 21}, {"time_limit", 60.5}};
  const LoadResult r = load(scene, limits);
  EXPECT_ERROR(r, "/render/spp", "must be <= 16 (max_spp)");
  EXPECT_ERROR(r, "/render/max_depth", "must be <= 20 (max_depth)");
  EXPECT_ERROR(r, "/render/rr_depth", "must be <= 20 (max_depth)");
  EXPECT_ERROR(r, "/render/time_limit", "must be <= 60 seconds (max_time_limit)");
}

TEST(Limits, DefaultSppLimit) {
  Json scene = base_scene();
  scene["render"] = {{"spp", 1 << 20}};
  EXPECT_LOADS(load(scene));
  scene["render"] = {{"spp", (1 << 20) + 1}};
  EXPECT_ERROR(load(scene), "/render/spp", "must be <= 1048576 (max_spp)");
}

TEST(Limits, Objects) {
  Limits limits;
  limits.max_objects = 3;
  Json scene = base_scene();
  scene["objects"].push_back(sphere(1));
  scene["objects"].push_back(sphere(2));
  EXPECT_LOADS(load(scene, limits));
  scene["objects"].push_back(sphere(3));
  EXPECT_ERROR(load(scene, limits), "/objects", "4 objects exceed the limit of 3 (max_objects)");
}

TEST(Limits, Materials) {
  Limits limits;
  limits.max_materials = 2;
  Json scene = base_scene();
  scene["materials"]["second"] = {{"type", "diffuse"}};
  EXPECT_LOADS(load(scene, limits));
  scene["materials"]["third"] = {{"type", "diffuse"}};
  EXPECT_ERROR(load(scene, limits), "/materials", "3 materials exceed the limit of 2 (max_materials)");
}

TEST(Limits, Lights) {
  Limits limits;
  limits.max_lights = 2;
  Json scene = base_scene();
  const Json light = {{"type", "point"}, {"position", {0, 2, 0}}, {"intensity", {1, 1, 1}}};
  scene["lights"] = {light, light};
  EXPECT_LOADS(load(scene, limits));
  scene["lights"].push_back(light);
  EXPECT_ERROR(load(scene, limits), "/lights", "3 lights exceed the limit of 2 (max_lights)");
}

TEST(Limits, TrianglesAcrossTheScene) {
  Limits limits;
  limits.max_triangles = 3;
  const Json two = {{"type", "mesh"},
                    {"positions", {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}},
                    {"indices", {0, 1, 2, 1, 3, 2}},
                    {"material", "white"}};
  Json one = two;
  one["indices"] = {0, 1, 2};
  Json scene = base_scene();
  scene["objects"].push_back(two);
  scene["objects"].push_back(one);
  EXPECT_LOADS(load(scene, limits));
  scene["objects"][2] = two;
  EXPECT_ERROR(load(scene, limits), "/objects/2/indices", "exceed the limit of 3 (max_triangles)");
}

TEST(Limits, HugeMeshIsRejectedBeforeReadingElements) {
  Limits limits;
  limits.max_vertices = 30;
  Json scene = base_scene();
  Json m = {{"type", "mesh"}, {"material", "white"}};
  m["positions"] = Json::array();
  for (int i = 0; i < 3 * 31; ++i) m["positions"].push_back("not a number");
  m["indices"] = {0, 1, 2};
  scene["objects"].push_back(m);
  const LoadResult r = load(scene, limits);
  EXPECT_ERROR(r, "/objects/1/positions", "the scene's mesh vertices exceed the limit of 30 (max_vertices)");
  EXPECT_EQ(r.errors.size(), 1u) << describe(r.errors);
}

}  // namespace
}  // namespace penumbra::test
