// The "instances" object: copies of a mesh object by index, each transform applied after the
// mesh's own; every mistake reported on its field.
#include <gtest/gtest.h>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

// base_scene() plus a one-triangle mesh at /objects/1 and its instances at /objects/2.
Json scene_with_instances(const Json& transforms) {
  Json s = base_scene();
  s["objects"].push_back(Json::parse(R"({"type": "mesh", "material": "white",
      "positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "indices": [0, 1, 2],
      "transform": {"translate": [0, 0, -1]}})"));
  s["objects"].push_back({{"type", "instances"}, {"mesh", 1}, {"transforms", transforms}});
  return s;
}

TEST(Instances, LoadsWithTransformsAfterTheMeshsOwn) {
  const LoadResult r = load(scene_with_instances(Json::parse(R"([
      {"translate": [2, 0, 0]},
      {"matrix": [0, -1, 0, 4,  1, 0, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]}])")));
  EXPECT_LOADS(r);
  const SceneInput& scene = r.request->scene;
  ASSERT_EQ(scene.objects.size(), 2u);  // the copies are not objects of their own
  ASSERT_EQ(scene.instances.size(), 1u);
  EXPECT_EQ(scene.instances[0].object, 1u);
  ASSERT_EQ(scene.instances[0].transforms.size(), 2u);
  // The mesh stands at its own place (z = -1); copy k maps it by transforms[k]. Positions are
  // relative to the camera (world_origin = [0, 0, 5]), and so are the copies' transforms:
  // vertex (1, 0, -1) -> (3, 0, -1) by the translation, -> (4, 1, -1) by the rotation + shift.
  const glm::dvec3 o = r.request->world_origin;
  const MeshDesc& mesh = std::get<MeshDesc>(scene.objects[1].shape);
  const glm::dvec3 vertex = glm::dvec3(mesh.positions[1]);  // restored to JSON coordinates
  auto copy = [&](int k) {
    const InstanceTransform& t = scene.instances[0].transforms[size_t(k)];
    return glm::dmat3(t.linear) * (vertex - o) + glm::dvec3(t.translation) + o;
  };
  EXPECT_NEAR(glm::length(copy(0) - glm::dvec3(3, 0, -1)), 0.0, 1e-6);
  EXPECT_NEAR(glm::length(copy(1) - glm::dvec3(4, 1, -1)), 0.0, 1e-6);
}

TEST(Instances, MeshMayComeLater) {
  Json s = base_scene();
  s["objects"].push_back(Json::parse(R"({"type": "instances", "mesh": 2, "transforms": [{}]})"));
  s["objects"].push_back(Json::parse(R"({"type": "mesh", "material": "white",
      "positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "indices": [0, 1, 2]})"));
  const LoadResult r = load(s);
  EXPECT_LOADS(r);
  ASSERT_EQ(r.request->scene.instances.size(), 1u);
  EXPECT_EQ(r.request->scene.instances[0].object, 1u);  // index among the renderer's objects
}

TEST(Instances, ReferenceErrorsNameTheMeshField) {
  Json s = scene_with_instances(Json::parse(R"([{}])"));
  s["objects"][2]["mesh"] = 7;
  EXPECT_ERROR(load(s), "/objects/2/mesh", "index 7 is out of range: /objects has 3 entries");
  s["objects"][2]["mesh"] = 0;
  EXPECT_ERROR(load(s), "/objects/2/mesh", "/objects/0 is a sphere: only a mesh can be instanced");
  s["objects"][2]["mesh"] = 2;
  EXPECT_ERROR(load(s), "/objects/2/mesh", "copies of copies are not supported");
  s["objects"][2]["mesh"] = -1;
  EXPECT_ERROR(load(s), "/objects/2/mesh", "must be >= 0");
  s["objects"][2]["mesh"] = "1";
  EXPECT_ERROR(load(s), "/objects/2/mesh", "");
  s["objects"][2].erase("mesh");
  EXPECT_ERROR(load(s), "/objects/2/mesh", "required");
}

TEST(Instances, EmittingMeshIsRefused) {
  Json s = scene_with_instances(Json::parse(R"([{}])"));
  s["objects"][1]["emission"] = {1, 1, 1};
  EXPECT_ERROR(load(s), "/objects/2/mesh", "/objects/1 emits light");
}

TEST(Instances, MovingMeshIsCopiedWithItsMotion) {
  Json s = scene_with_instances(Json::parse(R"([{"translate": [1, 0, 0]}])"));
  s["objects"][1]["velocity"] = {0, 1, 0};
  s["camera"]["shutter"] = {0, 1};
  EXPECT_LOADS(load(s));
}

TEST(Instances, FieldsOfShapesAreRefusedWithAReason) {
  Json s = scene_with_instances(Json::parse(R"([{}])"));
  s["objects"][2]["material"] = "white";
  s["objects"][2]["transform"] = {{"translate", {1, 0, 0}}};
  s["objects"][2]["emission"] = {1, 1, 1};
  const LoadResult r = load(s);
  EXPECT_ERROR(r, "/objects/2/material", "copies use their mesh's material");
  EXPECT_ERROR(r, "/objects/2/transform", "\"transforms\"");
  EXPECT_ERROR(r, "/objects/2/emission", "not supported");
  s = scene_with_instances(Json::parse(R"([{}])"));
  s["objects"][2]["transfroms"] = Json::array();
  EXPECT_ERROR(load(s), "/objects/2/transfroms", "did you mean 'transforms'");
}

TEST(Instances, TransformErrorsNameTheCopy) {
  EXPECT_ERROR(load(scene_with_instances(Json::parse(R"([{}, {"scale": 0}])"))),
               "/objects/2/transforms/1/scale", "nonzero");
  EXPECT_ERROR(load(scene_with_instances(Json::parse(R"([{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1]}])"))),
               "/objects/2/transforms/0/matrix", "invertible");
  EXPECT_ERROR(load(scene_with_instances(Json::parse(R"([{"translate": [1e19, 0, 0]}])"))),
               "/objects/2/transforms/0", "beyond world-space coordinates");
  EXPECT_ERROR(load(scene_with_instances(Json::parse(R"([{"scale": 1e-30}])"))),
               "/objects/2/transforms/0", "single precision");
  EXPECT_ERROR(load(scene_with_instances(Json::parse(R"({"translate": [1, 0, 0]})"))),
               "/objects/2/transforms", "array");
}

TEST(Instances, CountLimitOverTheWholeScene) {
  Limits limits;
  limits.max_instances = 3;
  Json s = scene_with_instances(Json::parse(R"([{}, {}])"));
  EXPECT_LOADS(load(s, limits));
  s["objects"].push_back({{"type", "instances"}, {"mesh", 1}, {"transforms", Json::parse("[{}]")}});
  EXPECT_LOADS(load(s, limits));  // 3 copies: at the limit
  s["objects"][3]["transforms"].push_back(Json::object());
  EXPECT_ERROR(load(s, limits), "/objects/3/transforms",
               "2 copies exceed the limit of 3 per scene (max_instances), 2 taken by earlier objects");
}

}  // namespace
}  // namespace penumbra::test
