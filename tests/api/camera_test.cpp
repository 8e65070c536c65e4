// Camera fields, defaults and degenerate configurations.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(Camera, DefaultsAndDerivedFocusDistance) {
  Json scene = base_scene();
  scene["camera"] = {{"position", {0, 3, 4}}, {"look_at", {0, 0, 0}}};
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const CameraDesc& c = r.request->scene.camera;
  EXPECT_EQ(c.up, vec3(0, 1, 0));
  EXPECT_EQ(c.fov_degrees, 40.f);
  EXPECT_EQ(c.aperture_radius, 0.f);
  EXPECT_FLOAT_EQ(c.focus_distance, 5.f);
  EXPECT_EQ(c.shutter_open, 0.f);
  EXPECT_EQ(c.shutter_close, 0.f);
}

TEST(Camera, AllFields) {
  Json scene = base_scene();
  scene["camera"] = Json::parse(R"({"position": [0, 1, 3.5], "look_at": [0, 1, 0], "up": [0, 2, 0],
    "fov": 30, "aperture_radius": 0.1, "focus_distance": 2, "shutter": [0.25, 1]})");
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const CameraDesc& c = r.request->scene.camera;
  EXPECT_EQ(c.position, vec3(0, 1, 3.5f));
  EXPECT_EQ(c.look_at, vec3(0, 1, 0));
  EXPECT_EQ(c.up, vec3(0, 1, 0));  // normalised
  EXPECT_EQ(c.fov_degrees, 30.f);
  EXPECT_EQ(c.aperture_radius, 0.1f);
  EXPECT_EQ(c.focus_distance, 2.f);
  EXPECT_EQ(c.shutter_open, 0.25f);
  EXPECT_EQ(c.shutter_close, 1.f);
}

TEST(Camera, LookAtEqualsPosition) {
  Json scene = base_scene();
  scene["camera"] = {{"position", {1, 2, 3}}, {"look_at", {1, 2, 3}}};
  EXPECT_ERROR(load(scene), "/camera/look_at", "must differ from position");
}

TEST(Camera, UpParallelToViewDirection) {
  Json scene = base_scene();
  scene["camera"] = {{"position", {0, 5, 0}}, {"look_at", {0, 0, 0}}};  // default up = +y
  EXPECT_ERROR(load(scene), "/camera/look_at", "parallel to the view direction");
  scene["camera"]["up"] = {0, -3, 0};
  EXPECT_ERROR(load(scene), "/camera/up", "parallel to the view direction");
  scene["camera"]["up"] = {0, 0, 0};
  EXPECT_ERROR(load(scene), "/camera/up", "must be a nonzero vector");
}

TEST(Camera, FieldRanges) {
  Json scene = base_scene();
  scene["camera"]["fov"] = 180;
  scene["camera"]["aperture_radius"] = -0.1;
  scene["camera"]["focus_distance"] = 0;
  EXPECT_ERROR(load(scene), "/camera/fov", "must be in (0, 180)");
  EXPECT_ERROR(load(scene), "/camera/aperture_radius", "must be >= 0");
  EXPECT_ERROR(load(scene), "/camera/focus_distance", "must be > 0");
  scene = base_scene();
  scene["camera"]["fov"] = 0;
  EXPECT_ERROR(load(scene), "/camera/fov", "must be in (0, 180)");
  scene["camera"]["fov"] = 179.9;
  EXPECT_LOADS(load(scene));
}

TEST(Camera, Shutter) {
  Json scene = base_scene();
  scene["camera"]["shutter"] = {1, 0};
  EXPECT_ERROR(load(scene), "/camera/shutter", "open <= close");
  scene["camera"]["shutter"] = {0, 1, 2};
  EXPECT_ERROR(load(scene), "/camera/shutter", "array of 2 numbers");
  scene["camera"]["shutter"] = {0, "1"};
  EXPECT_ERROR(load(scene), "/camera/shutter/1", "must be a number");
  scene["camera"]["shutter"] = {0.5, 0.5};
  EXPECT_LOADS(load(scene));
}

}  // namespace
}  // namespace penumbra::test
