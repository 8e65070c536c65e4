// `penumbra info`: what a scene or a mesh file holds, the files a scene reads, a memory
// estimate; unreadable or invalid files fail with the loader's messages.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/app/app_test_util.h"
#include "tests/renderer/io/mesh_file_test_util.h"

namespace penumbra::test {
namespace {

bool contains(const std::string& text, const std::string& fragment) {
  return text.find(fragment) != std::string::npos;
}

void write_file(const SceneFolder& folder, const std::string& name, const std::string& bytes) {
  std::ofstream(folder.file(name), std::ios::binary) << bytes;
}

TEST(Info, SceneWithAMeshFile) {
  SceneFolder folder;
  write_file(folder, "m.ply", write_ply(sample_polygon_mesh(), {PlyEncoding::kLittleEndian}));
  write_file(folder, "with_mesh.json", R"({"version": 1,
      "render": {"width": 100, "height": 50},
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "materials": {"white": {"type": "diffuse"}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white",
                   "emission": [1, 1, 1]},
                  {"type": "mesh", "file": "m.ply", "material": "white"},
                  {"type": "quad", "origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0], "material": "white"}],
      "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1]}]})");
  const CommandResult r = run_penumbra(folder, "info with_mesh.json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "with_mesh.json: scene, 100 x 50 pixels, 64 spp\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "  objects     3: 1 sphere, 1 quad, 1 mesh; 1 emitting\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "  triangles   6\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "  vertices    8\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "  lights      1 point light; environment black\n")) << r.output;
  EXPECT_TRUE(contains(
      r.output, "    /objects/1/file  m.ply: 6 triangles (3 faces), 8 vertices, normals, uvs\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "  memory      about ")) << r.output;
  EXPECT_TRUE(contains(r.output, "film 390.6 KiB")) << r.output;  // 5000 pixels x 80 bytes
}

// An environment map: the line says so (not "black"), and the estimate counts its texels in
// the input and its sampling tables in the light, which shares the input's texels (512 x 256:
// 1.5 MiB and 1.1 MiB).
TEST(Info, SceneWithAnEnvironmentMap) {
  SceneFolder folder;
  std::filesystem::copy_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/sky_sun.hdr",
                             folder.file("sky.hdr"));
  write_file(folder, "sky.json", R"({"version": 1,
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "environment": {"map": "sky.hdr"},
      "materials": {"white": {"type": "diffuse"}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}]})");
  const CommandResult r = run_penumbra(folder, "info sky.json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "  lights      none; environment map 512 x 256\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "  files       1\n    /environment/map  sky.hdr: 512 x 256, 3 channels, float\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "scene input 1.5 MiB, renderer copies 1.1 MiB")) << r.output;
}

// Image textures: each file once (the first field naming it), with its header's size, channels
// and storage, and their decoded size in the estimate (a 128 x 128 RGB PNG as 8-bit texels,
// 48 KiB; a 64 x 64 grey one, 4 KiB).
TEST(Info, SceneWithTextures) {
  SceneFolder folder;
  const std::string textures = std::string(PENUMBRA_SOURCE_DIR) + "/tests/accuracy/scenes/textures/";
  std::filesystem::copy_file(textures + "wood.png", folder.file("wood.png"));
  std::filesystem::copy_file(textures + "rough.png", folder.file("rough.png"));
  write_file(folder, "textured.json", R"({"version": 1,
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "environment": {"radiance": [1, 1, 1]},
      "materials": {"a": {"type": "diffuse", "color": {"texture": "wood.png"}},
                    "b": {"type": "conductor", "roughness": {"texture": "rough.png"},
                          "color": {"texture": "wood.png"}}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "a"},
                  {"type": "sphere", "center": [2, 0, 0], "radius": 1, "material": "b"}]})");
  const CommandResult r = run_penumbra(folder, "info textured.json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "  files       2\n"
                       "    /materials/a/color/texture  wood.png: 128 x 128, 3 channels, 8-bit\n"
                       "    /materials/b/roughness/texture  rough.png: 64 x 64, 1 channel, 8-bit\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, ", textures 52.0 KiB, film ")) << r.output;
}

TEST(Info, SceneWithInstances) {
  SceneFolder folder;
  write_file(folder, "copies.json", R"({"version": 1,
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "environment": {"radiance": [1, 1, 1]},
      "materials": {"white": {"type": "diffuse"}},
      "objects": [{"type": "mesh", "material": "white", "positions": [0, 0, 0, 1, 0, 0, 0, 1, 0],
                   "indices": [0, 1, 2]},
                  {"type": "instances", "mesh": 0, "transforms": [{"translate": [2, 0, 0]}, {}]},
                  {"type": "instances", "mesh": 0, "transforms": [{"scale": 2}]}]})");
  const CommandResult r = run_penumbra(folder, "info copies.json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "  objects     3: 1 mesh, 2 instances objects; 0 emitting\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "  triangles   1\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "  instances   3 copies of 1 mesh, 4 triangles drawn in all\n"))
      << r.output;
  const CommandResult v = run_penumbra(folder, "validate copies.json");
  EXPECT_TRUE(contains(v.output, "3 objects, 1 triangles, 0 lights, 0 emitting objects, 3 instanced copies"))
      << v.output;
}

TEST(Info, MeshFiles) {
  SceneFolder folder;
  PolygonMesh m = sample_polygon_mesh();
  m.normals.clear();
  m.faces.push_back({0, 1, 1});
  write_file(folder, "m.ply", write_ply(m, {PlyEncoding::kBigEndian}));
  write_file(folder, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n");
  const CommandResult r = run_penumbra(folder, "info m.ply t.obj");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "m.ply: mesh file (PLY)\n"
                       "  faces       4\n"
                       "  triangles   7 (1 degenerate, dropped when rendered)\n"
                       "  vertices    8\n"
                       "  normals     no (shaded flat)\n"
                       "  uvs         yes\n"
                       "  bounds      [0, 0, -0.25] to [3.5, 1.5, 0.5]\n"
                       "  memory      about "))
      << r.output;
  EXPECT_TRUE(contains(r.output, "t.obj: mesh file (OBJ)\n  faces       1\n")) << r.output;
}

TEST(Info, BadFilesFail) {
  SceneFolder folder;
  write_file(folder, "bad.ply", "ply\nformat ascii 1.0\nelement vertex 1\nend_header\n");
  write_file(folder, "bad.json",
             R"({"version": 1, "camera": {"position": [0, 0, 1], "look_at": [0, 0, 1]}})");
  CommandResult r = run_penumbra(folder, "info bad.ply");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.output, "bad.ply: the file has no face element (a point cloud is not a mesh)\n");
  r = run_penumbra(folder, "info bad.json scene.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.output, "bad.json: /camera/look_at: must differ from position"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "scene.json: scene, 16 x 12 pixels, 2 spp\n"))
      << r.output;  // still reported
  r = run_penumbra(folder, "info notes.txt");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.output, "notes.txt: unknown kind of file")) << r.output;
  EXPECT_EQ(run_penumbra(folder, "info").exit_code, 2);
  EXPECT_EQ(run_penumbra(folder, "info --bogus scene.json").exit_code, 2);
}

}  // namespace
}  // namespace penumbra::test
