// "file" on a mesh object: PLY and OBJ meshes from the scene's folder, placed by the object's
// transform exactly as the same inline mesh would be; every problem on the "file" field, naming
// the file; the scene's triangle and vertex limits and the file-size limit apply.
#include <unistd.h>

#include <fstream>
#include <variant>

#include "tests/api/scene_test_util.h"
#include "tests/renderer/io/mesh_file_test_util.h"

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_.root =
        fs::temp_directory_path() / ("penumbra_mesh_files_" + std::to_string(::getpid()));
    fs::create_directories(folder_.root);
  }
  void TearDown() override { fs::remove_all(folder_.root); }

  void write(const std::string& name, const std::string& bytes) {
    std::ofstream(folder_.root / name, std::ios::binary) << bytes;
  }
  LoadResult load_in_folder(const Json& scene, const Limits& limits = {}) {
    LoadResult r = load_scene(scene.dump(), limits, {}, folder_);
    if (r.request) restore_json_coordinates(*r.request);
    return r;
  }
  // base_scene() plus a mesh object naming `file`, with `extra` fields.
  static Json scene_with(const std::string& file, const Json& extra = Json::object()) {
    Json scene = base_scene();
    Json mesh = {{"type", "mesh"}, {"file", file}, {"material", "white"}};
    mesh.update(extra);
    scene["objects"].push_back(mesh);
    return scene;
  }
  static const MeshDesc& mesh_of(const LoadResult& r, std::size_t object = 1) {
    return std::get<MeshDesc>(r.request->scene.objects.at(object).shape);
  }

  AssetFolder folder_;
};

// The inline equivalent of sample_polygon_mesh(), triangulated as the readers do.
Json inline_sample_mesh() {
  const PolygonMesh m = sample_polygon_mesh();
  Json positions = Json::array(), normals = Json::array(), uvs = Json::array(),
       indices = Json::array();
  for (size_t i = 0; i < m.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) positions.push_back(m.positions[i][k]);
    for (int k = 0; k < 3; ++k) normals.push_back(m.normals[i][k]);
    for (int k = 0; k < 2; ++k) uvs.push_back(m.uvs[i][k]);
  }
  for (const auto& face : m.faces)
    for (size_t k = 1; k + 1 < face.size(); ++k)
      indices.insert(indices.end(), {face[0], face[k], face[k + 1]});
  return {{"type", "mesh"}, {"positions", positions}, {"normals", normals},
          {"uvs", uvs},     {"indices", indices},     {"material", "white"}};
}

TEST_F(MeshFiles, AFileMeshEqualsTheSameInlineMesh) {
  write("m.ply", write_ply(sample_polygon_mesh(), {PlyEncoding::kBigEndian}));
  const Json transform = {{"scale", {2, 1, 0.5}},
                          {"rotate", {{"axis", {1, 1, 0}}, {"degrees", 30}}},
                          {"translate", {1, 2, 3}}};
  Json scene = scene_with("m.ply", {{"transform", transform}});
  Json inline_mesh = inline_sample_mesh();
  inline_mesh["transform"] = transform;
  scene["objects"].push_back(inline_mesh);
  const LoadResult r = load_in_folder(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const MeshDesc& file = mesh_of(r, 1);
  const MeshDesc& json = mesh_of(r, 2);
  EXPECT_EQ(file.positions, json.positions);
  EXPECT_EQ(file.indices, json.indices);
  EXPECT_EQ(file.normals, json.normals);
  EXPECT_EQ(file.uvs, json.uvs);
  EXPECT_EQ(file.uvs, sample_polygon_mesh().uvs);                    // uvs are not transformed
  EXPECT_NE(file.positions[1], sample_polygon_mesh().positions[1]);  // positions are
  ASSERT_EQ(r.request->assets.size(), 1u);
  EXPECT_EQ(r.request->assets[0].pointer, "/objects/1/file");
  EXPECT_EQ(r.request->assets[0].path, "m.ply");
  EXPECT_EQ(r.request->assets[0].summary, "6 triangles (3 faces), 8 vertices, normals, uvs");
}

TEST_F(MeshFiles, ObjInASubfolder) {
  fs::create_directories(folder_.root / "meshes");
  write("meshes/t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0.25\nf 1/1 2/1 3/1\n");
  const LoadResult r = load_in_folder(scene_with("meshes/t.obj"));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(mesh_of(r).indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(mesh_of(r).uvs, std::vector<vec2>(3, vec2(0, 0.75f)));
  EXPECT_TRUE(mesh_of(r).normals.empty());  // shaded with face normals, as inline meshes
}

TEST_F(MeshFiles, ErrorsAreOnTheFileFieldAndNameTheFile) {
  PolygonMesh bad_index = sample_polygon_mesh();
  bad_index.faces[1] = {1, 9, 2};
  write("bad.ply", write_ply(bad_index));
  EXPECT_ERROR(load_in_folder(scene_with("bad.ply")), "/objects/1/file",
               "'bad.ply': face 2: vertex index 9 is out of range");
  write("cut.ply", write_ply(sample_polygon_mesh(), {PlyEncoding::kLittleEndian})
                       .substr(0, 560));  // inside face 2
  EXPECT_ERROR(load_in_folder(scene_with("cut.ply")), "/objects/1/file", "'cut.ply': truncated");
  write("nan.obj", "v 0 0 0\nv 1e40 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_ERROR(load_in_folder(scene_with("nan.obj")), "/objects/1/file",
               "'nan.obj': vertex 2: the position is not finite");
  EXPECT_ERROR(load_in_folder(scene_with("none.ply")), "/objects/1/file", "no such file");
  EXPECT_ERROR(load_in_folder(scene_with("../escape.ply")), "/objects/1/file",
               "'..' is not allowed");
  EXPECT_ERROR(load_in_folder(scene_with("mesh.stl")), "/objects/1/file",
               "must name a .ply or .obj file");
  EXPECT_ERROR(load_in_folder(scene_with("m.ply", {{"positions", {0, 0, 0}}})),
               "/objects/1/positions", "either \"file\" or inline arrays");
  EXPECT_ERROR(load_in_folder(scene_with("m.ply", {{"file", 3}})), "/objects/1/file",
               "must be a string");
  // Without an asset folder (the service, for now) no file can be named.
  EXPECT_ERROR(load(scene_with("m.ply")), "/objects/1/file", "no asset folder");
}

TEST_F(MeshFiles, DegenerateTrianglesAreDroppedAndCounted) {
  PolygonMesh m = sample_polygon_mesh();
  m.faces.push_back({0, 1, 1});  // a repeated corner: degenerate
  m.faces.push_back({0, 1, 4});  // fine
  m.faces.push_back({0, 0, 0});  // degenerate
  write("d.ply", write_ply(m));
  const LoadResult r = load_in_folder(scene_with("d.ply"));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_TRUE(has(r.warnings, "/objects/1/file",
                  "'d.ply': dropped 2 degenerate (zero-area) triangle(s); the first is triangle 7"))
      << describe(r.warnings);
  EXPECT_EQ(mesh_of(r).indices.size(), 3u * 7);
  // All degenerate: an error.
  PolygonMesh flat = sample_polygon_mesh();
  flat.faces = {{0, 1, 1}};
  write("flat.ply", write_ply(flat));
  EXPECT_ERROR(load_in_folder(scene_with("flat.ply")), "/objects/1/file",
               "'flat.ply': all 1 triangles are degenerate");
}

TEST_F(MeshFiles, ZeroNormalsAreRepairedWithAWarningNamingTheVertex) {
  PolygonMesh m = sample_polygon_mesh();
  m.normals[2] = vec3(0.f);
  write("z.ply", write_ply(m));
  const LoadResult r = load_in_folder(scene_with("z.ply"));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_TRUE(has(r.warnings, "/objects/1/file", "1 zero-length normal(s) replaced"));
  EXPECT_TRUE(has(r.warnings, "/objects/1/file", "the first is vertex 3"));
  EXPECT_NEAR(glm::length(mesh_of(r).normals[2]), 1.f, 1e-6f);
}

TEST_F(MeshFiles, TransformOutOfRangeBlamesTheTransform) {
  write("m.ply", write_ply(sample_polygon_mesh()));
  EXPECT_ERROR(load_in_folder(scene_with("m.ply", {{"transform", {{"scale", 1e20}}}})),
               "/objects/1/transform", "'m.ply': world-space positions must be within");
}

TEST_F(MeshFiles, LimitsCountInlineAndFileMeshesTogether) {
  write("m.ply", write_ply(sample_polygon_mesh()));  // 6 triangles, 8 vertices
  Json scene = scene_with("m.ply");
  scene["objects"].push_back(Json::parse(
      R"({"type": "mesh", "positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0,1,2], "material": "white"})"));
  Limits limits;
  limits.max_triangles = 7;
  limits.max_vertices = 11;
  EXPECT_LOADS(load_in_folder(scene, limits));
  limits.max_triangles = 6;
  EXPECT_ERROR(load_in_folder(scene, limits), "/objects/2/indices",
               "exceed the limit of 6 (max_triangles)");
  limits.max_triangles = 5;  // now the file itself is over
  EXPECT_ERROR(load_in_folder(scene, limits), "/objects/1/file",
               "takes the mesh past the limit of 5 triangles");
  limits.max_triangles = 7;
  limits.max_vertices = 10;
  EXPECT_ERROR(load_in_folder(scene, limits), "/objects/2/positions",
               "exceed the limit of 10 (max_vertices)");
  limits.max_vertices = 7;
  EXPECT_ERROR(load_in_folder(scene, limits), "/objects/1/file", "announces 8 vertices; at most 7");
  limits.max_vertices = 11;
  limits.max_mesh_file_bytes = 100;
  EXPECT_ERROR(load_in_folder(scene, limits), "/objects/1/file", "bytes; at most 100");
}

TEST(InlineUvs, AreReadAndChecked) {
  Json scene = base_scene();
  Json mesh =
      Json::parse(R"({"type": "mesh", "positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0,1,2],
                              "uvs": [0,0, 1,0, 0,1], "material": "white"})");
  scene["objects"].push_back(mesh);
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(std::get<MeshDesc>(r.request->scene.objects[1].shape).uvs,
            (std::vector<vec2>{{0, 0}, {1, 0}, {0, 1}}));
  scene["objects"][1]["uvs"] = {0, 0, 1, 0};
  EXPECT_ERROR(load(scene), "/objects/1/uvs", "must hold 2 numbers per vertex (6), got 4");
  scene["objects"][1]["uvs"] = {0, 0, 1, 0, 0, "one"};
  EXPECT_ERROR(load(scene), "/objects/1/uvs/5", "must be a number");
}

}  // namespace
}  // namespace penumbra::test
