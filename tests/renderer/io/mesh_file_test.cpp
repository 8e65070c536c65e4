// read_mesh_file: the format follows the extension (any case), the file's size is checked
// before it is read, and every error names the file as the caller named it.
#include "renderer/io/mesh_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "tests/renderer/io/mesh_file_test_util.h"

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class MeshFileRead : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_mesh_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }
  std::string error(const fs::path& path, const MeshFileLimits& limits = {}) {
    try {
      read_mesh_file(path, "'shown name'", limits);
    } catch (const MeshFileError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(MeshFileRead, ExtensionChoosesTheFormat) {
  const std::string ply = write_ply(sample_polygon_mesh(), {PlyEncoding::kLittleEndian});
  EXPECT_EQ(read_mesh_file(write("a.ply", ply), "a.ply").mesh.indices.size(), 18u);
  EXPECT_EQ(read_mesh_file(write("b.PLY", ply), "b.PLY").faces, 3);
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  EXPECT_EQ(read_mesh_file(write("c.Obj", obj), "c.Obj").mesh.indices.size(), 3u);
  // The bytes decide nothing: an OBJ named .ply is a malformed PLY.
  EXPECT_EQ(error(write("d.ply", obj)), "'shown name': not a PLY file (it must begin with 'ply')");
  EXPECT_EQ(error(write("e.stl", obj)),
            "'shown name': unknown mesh file type '.stl': expected .ply or .obj");
  EXPECT_TRUE(is_mesh_file_name("x.OBJ"));
  EXPECT_FALSE(is_mesh_file_name("x.gltf"));
}

TEST_F(MeshFileRead, SizeLimitAndMissingFiles) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const fs::path path = write("a.obj", obj);
  MeshFileLimits limits;
  limits.max_file_bytes = int64_t(obj.size());
  EXPECT_EQ(error(path, limits), "");
  limits.max_file_bytes -= 1;
  EXPECT_EQ(error(path, limits), "'shown name': the file has 32 bytes; at most 31 are allowed");
  EXPECT_EQ(error(dir_ / "missing.obj"), "'shown name': cannot open the file");
}

}  // namespace
}  // namespace penumbra::test
