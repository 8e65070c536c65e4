// Degenerate geometry: zero-area quads are errors; degenerate triangles inside a mesh are
// dropped with a warning; bad indices and sizes are errors on the element's pointer.
#include <variant>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

Json mesh(Json positions, Json indices) {
  return {{"type", "mesh"}, {"positions", positions}, {"indices", indices}, {"material", "white"}};
}

const MeshDesc& mesh_of(const LoadResult& r, std::size_t object) {
  return std::get<MeshDesc>(r.request->scene.objects.at(object).shape);
}

TEST(Geometry, ZeroAreaQuad) {
  Json scene = base_scene();
  scene["objects"].push_back(Json::parse(
      R"({"type": "quad", "origin": [0,0,0], "u": [1,0,0], "v": [-2,0,0], "material": "white"})"));
  scene["objects"].push_back(Json::parse(
      R"({"type": "quad", "origin": [0,0,0], "u": [0,0,0], "v": [0,1,0], "material": "white"})"));
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/1", "zero-area quad");
  EXPECT_ERROR(r, "/objects/2", "zero-area quad");
}

TEST(Geometry, QuadIsPassedThrough) {
  Json scene = base_scene();
  scene["objects"].push_back(Json::parse(
      R"({"type": "quad", "origin": [1,2,3], "u": [1,0,0], "v": [0,0,-1], "material": "white"})"));
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& quad = std::get<QuadDesc>(r.request->scene.objects[1].shape);
  EXPECT_EQ(quad.origin, vec3(1, 2, 3));
  EXPECT_EQ(quad.u, vec3(1, 0, 0));
  EXPECT_EQ(quad.v, vec3(0, 0, -1));
}

TEST(Geometry, IndicesOutOfRangeNegativeOrFractional) {
  Json scene = base_scene();
  scene["objects"].push_back(mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 3, -1, 1.5, "2"}));
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/1/indices/2", "index 3 is out of range: the mesh has 3 vertices");
  EXPECT_ERROR(r, "/objects/1/indices/3", "index -1 is out of range");
  EXPECT_ERROR(r, "/objects/1/indices/4", "must be an integer");
  EXPECT_ERROR(r, "/objects/1/indices/5", "must be an integer (got a string)");
}

TEST(Geometry, ArraySizes) {
  Json scene = base_scene();
  scene["objects"].push_back(mesh({0, 0, 0, 1, 0}, {0, 1, 2}));
  scene["objects"].push_back(mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1}));
  scene["objects"].push_back(mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, Json::array()));
  scene["objects"].push_back(mesh(Json::array(), {0, 1, 2}));
  Json with_normals = mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  with_normals["normals"] = {0, 0, 1};
  scene["objects"].push_back(with_normals);
  scene["objects"].push_back(mesh({0, 0, 0, 1, 0, 0, 0, 1, "z"}, {0, 1, 2}));
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/1/positions", "multiple of 3");
  EXPECT_ERROR(r, "/objects/2/indices", "multiple of 3");
  EXPECT_ERROR(r, "/objects/3/indices", "at least one triangle");
  EXPECT_ERROR(r, "/objects/4/positions", "at least one vertex");
  EXPECT_ERROR(r, "/objects/5/normals", "must have as many numbers as \"positions\"");
  EXPECT_ERROR(r, "/objects/6/positions/8", "must be a number (got a string)");
}

TEST(Geometry, DegenerateTrianglesAreDroppedWithAWarning) {
  Json scene = base_scene();
  // Triangle 1 repeats a vertex; triangle 2 is collinear; triangle 0 and 3 are fine.
  scene["objects"].push_back(
      mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0}, {0, 1, 2, 0, 0, 1, 0, 1, 3, 2, 1, 3}));
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_TRUE(has(r.warnings, "/objects/1/indices/3", "dropped 2 degenerate")) << describe(r.warnings);
  const MeshDesc& m = mesh_of(r, 1);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3}));
  EXPECT_EQ(m.positions.size(), 4u);
}

TEST(Geometry, AllTrianglesDegenerateIsAnError) {
  Json scene = base_scene();
  scene["objects"].push_back(mesh({0, 0, 0, 1, 0, 0, 2, 0, 0}, {0, 1, 2, 1, 1, 1}));
  EXPECT_ERROR(load(scene), "/objects/1/indices", "all 2 triangles are degenerate");
}

TEST(Geometry, ZeroLengthNormalsAreRepairedFromFaces) {
  Json scene = base_scene();
  Json m = mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5}, {0, 1, 2});
  m["normals"] = {0, 0, 0, 0, 0, 2, 0, 0, 1, 0, 0, 0};
  scene["objects"].push_back(m);
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_TRUE(has(r.warnings, "/objects/1/normals/0", "2 zero-length normal(s) replaced"))
      << describe(r.warnings);
  const MeshDesc& shape = mesh_of(r, 1);
  ASSERT_EQ(shape.normals.size(), 4u);
  EXPECT_EQ(shape.normals[0], vec3(0, 0, 1));  // the face normal (counter-clockwise in xy)
  EXPECT_EQ(shape.normals[1], vec3(0, 0, 1));  // normalised
  EXPECT_EQ(shape.normals[3], vec3(0, 0, 1));  // unused vertex: any unit vector
}

TEST(Geometry, MeshIsPassedThrough) {
  Json scene = base_scene();
  Json m = mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  m["normals"] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  m["velocity"] = {1, 2, 3};
  m["acceleration"] = {0, -9.81, 0};
  m["emission"] = {4, 5, 6};
  scene["objects"].push_back(m);
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_TRUE(r.warnings.empty()) << describe(r.warnings);
  const ObjectDesc& o = r.request->scene.objects[1];
  EXPECT_EQ(o.velocity, vec3(1, 2, 3));
  EXPECT_EQ(o.acceleration, vec3(0, -9.81f, 0));
  EXPECT_EQ(o.emission, Spectrum(4, 5, 6));
  const MeshDesc& shape = mesh_of(r, 1);
  EXPECT_EQ(shape.positions[1], vec3(1, 0, 0));
  EXPECT_EQ(shape.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(Geometry, SphereIsPassedThrough) {
  const LoadResult r = load(base_scene());
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& sphere = std::get<SphereDesc>(r.request->scene.objects[0].shape);
  EXPECT_EQ(sphere.center, vec3(0));
  EXPECT_EQ(sphere.radius, 1.f);
}

}  // namespace
}  // namespace penumbra::test
