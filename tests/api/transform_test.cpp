// Object transforms: scale -> rotate -> translate, row-major matrices, normals by the inverse
// transpose, spheres only under similarities.
#include <variant>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

void expect_near(const vec3& a, const vec3& b, float tolerance = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tolerance) << "x";
  EXPECT_NEAR(a.y, b.y, tolerance) << "y";
  EXPECT_NEAR(a.z, b.z, tolerance) << "z";
}

LoadResult load_with_quad_transform(const Json& transform) {
  Json scene = base_scene();
  scene["objects"].push_back({{"type", "quad"}, {"origin", {1, 0, 0}}, {"u", {1, 0, 0}},
                              {"v", {0, 1, 0}}, {"material", "white"}, {"transform", transform}});
  return load(scene);
}

TEST(Transform, ScaleThenRotateThenTranslate) {
  // Scale x by 2 -> (2,0,0); rotate 90 degrees about +z -> (0,2,0); translate -> (0,2,5).
  const LoadResult r = load_with_quad_transform(Json::parse(
      R"({"translate": [0, 0, 5], "rotate": {"axis": [0, 0, 3], "degrees": 90}, "scale": [2, 1, 1]})"));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& quad = std::get<QuadDesc>(r.request->scene.objects[1].shape);
  expect_near(quad.origin, vec3(0, 2, 5));  // a point: all three steps
  expect_near(quad.u, vec3(0, 2, 0));       // a vector: no translation
  expect_near(quad.v, vec3(-1, 0, 0));
}

TEST(Transform, UniformScaleAsNumber) {
  const LoadResult r = load_with_quad_transform({{"scale", 3}});
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& quad = std::get<QuadDesc>(r.request->scene.objects[1].shape);
  expect_near(quad.origin, vec3(3, 0, 0));
  expect_near(quad.v, vec3(0, 3, 0));
}

TEST(Transform, MatrixIsRowMajor) {
  // Row-major: the translation is the last column of the first three rows.
  const LoadResult r = load_with_quad_transform(
      {{"matrix", {0, -1, 0, 10, 1, 0, 0, 20, 0, 0, 1, 30, 0, 0, 0, 1}}});
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& quad = std::get<QuadDesc>(r.request->scene.objects[1].shape);
  expect_near(quad.origin, vec3(10, 21, 30));  // (1,0,0) rotated to (0,1,0), then translated
  expect_near(quad.u, vec3(0, 1, 0));
  expect_near(quad.v, vec3(-1, 0, 0));
}

TEST(Transform, MatrixMustBeAffineInvertibleAndAlone) {
  Json scene = base_scene();
  auto with = [&](Json transform) {
    Json s = scene;
    s["objects"][0]["transform"] = transform;
    return load(s);
  };
  EXPECT_ERROR(with({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}}}),
               "/objects/0/transform/matrix", "last row must be [0, 0, 0, 1]");
  EXPECT_ERROR(with({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}}}),
               "/objects/0/transform/matrix", "must be invertible");
  EXPECT_ERROR(with({{"matrix", {1, 0, 0}}}), "/objects/0/transform/matrix", "16 numbers");
  EXPECT_ERROR(with({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, "1"}}}),
               "/objects/0/transform/matrix/15", "must be a number");
  EXPECT_ERROR(with({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}, {"scale", 2}}),
               "/objects/0/transform/scale", "cannot be combined");
}

TEST(Transform, ComponentErrors) {
  Json scene = base_scene();
  scene["objects"][0]["transform"] =
      Json::parse(R"({"scale": [1, 0, 1], "rotate": {"axis": [0, 0, 0], "degrees": 45}})");
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/0/transform/scale/1", "must be nonzero");
  EXPECT_ERROR(r, "/objects/0/transform/rotate/axis", "must be a nonzero vector");
  scene["objects"][0]["transform"] = {{"scale", 0}, {"rotate", {{"axis", {0, 1, 0}}}}};
  const LoadResult r2 = load(scene);
  EXPECT_ERROR(r2, "/objects/0/transform/scale", "must be nonzero");
  EXPECT_ERROR(r2, "/objects/0/transform/rotate/degrees", "required field is missing");
}

TEST(Transform, MeshNormalsUseTheInverseTranspose) {
  Json scene = base_scene();
  // A plane tilted 45 degrees in xy; its normal (1,-1,0)/sqrt2. Scaling x by 2 makes the plane
  // steeper; the correct normal is inverse-transpose * n = (1/2, -1, 0), normalised.
  scene["objects"].push_back(Json::parse(R"({"type": "mesh", "material": "white",
    "positions": [0,0,0, 1,1,0, 0,0,1], "indices": [0,1,2],
    "normals": [1,-1,0, 1,-1,0, 1,-1,0], "transform": {"scale": [2, 1, 1]}})"));
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& mesh = std::get<MeshDesc>(r.request->scene.objects[1].shape);
  expect_near(mesh.positions[1], vec3(2, 1, 0));
  const vec3 expected = glm::normalize(vec3(0.5f, -1.f, 0.f));
  expect_near(mesh.normals[0], expected);
  // And it is perpendicular to the transformed surface.
  EXPECT_NEAR(glm::dot(mesh.normals[0], mesh.positions[1] - mesh.positions[0]), 0.f, 1e-5f);
}

TEST(Transform, SphereUnderSimilarity) {
  Json scene = base_scene();
  scene["objects"][0]["center"] = {1, 0, 0};
  scene["objects"][0]["transform"] = Json::parse(
      R"({"scale": 2, "rotate": {"axis": [0, 1, 0], "degrees": 90}, "translate": [0, 1, 0]})");
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& sphere = std::get<SphereDesc>(r.request->scene.objects[0].shape);
  // (1,0,0) scaled to (2,0,0), rotated about +y by 90 degrees to (0,0,-2), translated.
  expect_near(sphere.center, vec3(0, 1, -2));
  EXPECT_NEAR(sphere.radius, 2.f, 1e-6f);
}

TEST(Transform, SphereRejectsNonSimilarity) {
  Json scene = base_scene();
  scene["objects"][0]["transform"] = {{"scale", {1, 2, 1}}};
  EXPECT_ERROR(load(scene), "/objects/0/transform", "must be a similarity");
  // Shear through a matrix.
  scene["objects"][0]["transform"] = {{"matrix", {1, 0.5, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  EXPECT_ERROR(load(scene), "/objects/0/transform", "must be a similarity");
  // A mirror with uniform scale is a similarity.
  scene["objects"][0]["transform"] = {{"scale", {-2, 2, 2}}};
  EXPECT_LOADS(load(scene));
}

}  // namespace
}  // namespace penumbra::test
