// The loader hands the renderer positions relative to the camera, subtracted in double
// precision, so a scene far from the JSON origin keeps single-precision accuracy.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(Rebasing, PositionsAreRelativeToTheCamera) {
  Json scene = base_scene();
  const double far = 1e6;
  scene["camera"] = {{"position", {far, far + 1, far + 5}}, {"look_at", {far, far + 1, far}}};
  scene["objects"][0]["center"] = {far + 0.25, far + 1.5, far - 0.125};
  scene["objects"].push_back(Json::parse(
      R"({"type": "quad", "origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 0, -1], "material": "white",
          "transform": {"translate": [1000000.5, 1000000, 1000000.25]}})"));
  scene["lights"] = Json::parse(R"([{"type": "point", "position": [1000000.75, 1000002, 999999.5],
                                     "intensity": [1, 1, 1]}])");
  const LoadResult r = load_scene(scene.dump());
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const SceneRequest& q = *r.request;
  EXPECT_EQ(q.world_origin, glm::dvec3(far, far + 1, far + 5));
  EXPECT_EQ(q.scene.camera.position, vec3(0.f));
  EXPECT_EQ(q.scene.camera.look_at, vec3(0, 0, -5));
  // Offsets below float resolution at 1e6 (0.0625) survive exactly.
  EXPECT_EQ(std::get<SphereDesc>(q.scene.objects[0].shape).center, vec3(0.25f, 0.5f, -5.125f));
  EXPECT_EQ(std::get<QuadDesc>(q.scene.objects[1].shape).origin, vec3(0.5f, -1.f, -4.75f));
  EXPECT_EQ(std::get<QuadDesc>(q.scene.objects[1].shape).u, vec3(1, 0, 0));
  EXPECT_EQ(std::get<PointLightDesc>(q.scene.lights[0]).position, vec3(0.75f, 1.f, -5.5f));
}

}  // namespace
}  // namespace penumbra::test
