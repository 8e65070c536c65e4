#pragma once
// Mesh files (PLY, OBJ) read from untrusted bytes. Every count a file announces is checked
// against explicit limits and against the bytes that could hold it before anything is allocated
// from it, so a header claiming 2^40 faces costs nothing; every error names the file.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/scene/scene_input.h"

namespace penumbra {

struct MeshFileLimits {
  int64_t max_file_bytes = int64_t(1) << 30;
  int64_t max_vertices = 12'000'000;  // distinct vertices after reading (at most 2^32 - 1)
  int64_t max_triangles = 4'000'000;  // after fan triangulation
};

// A mesh as its file stores it, in the file's (object) space: polygons fan-triangulated from
// their first vertex, indices checked against the vertex count, every number finite in single
// precision. Degenerate triangles are kept: whether one is degenerate depends on the transform
// that places the mesh, so the caller judges it.
struct MeshFile {
  MeshDesc mesh;
  int64_t faces = 0;                  // polygons in the file, before triangulation
  std::vector<std::string> warnings;  // e.g. attributes given for some corners only, ignored
};

// "<name>: <reason>"; `name` is the file as the user named it.
struct MeshFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Reads `path` (at most limits.max_file_bytes) and parses it by its extension, ".ply" or ".obj"
// (case-insensitive). `name` is how errors refer to the file. Throws MeshFileError.
MeshFile read_mesh_file(const std::filesystem::path& path, const std::string& name,
                        const MeshFileLimits& limits = {});

// True for the extensions read_mesh_file knows.
bool is_mesh_file_name(const std::filesystem::path& path);

namespace mesh_file_detail {

[[noreturn]] void fail(const std::string& name, const std::string& reason);

// Builds MeshFile::mesh face by face for the readers: fan triangulation from the first corner,
// the triangle cap checked before each face is added, corners checked against the vertex count.
class FaceSink {
 public:
  FaceSink(const std::string& name, const MeshFileLimits& limits, uint64_t vertex_count,
           std::vector<uint32_t>& indices)
      : name_(name), limits_(limits), vertex_count_(vertex_count), indices_(indices) {}

  // Throws unless a face of `count` corners may be added: at least 3, and its count - 2
  // triangles within the cap. Readers call it before allocating room for the corners.
  void check(uint64_t count, int64_t face) const;
  // `corners` index the vertices (range-checked here); `face` counts from 0 (messages from 1).
  void add(const int64_t* corners, uint64_t count, int64_t face);
  int64_t triangles() const { return triangles_; }

 private:
  const std::string& name_;
  const MeshFileLimits& limits_;
  uint64_t vertex_count_;
  std::vector<uint32_t>& indices_;
  int64_t triangles_ = 0;
};

// Throws unless every position, normal and uv of `mesh` is finite.
void check_finite(const std::string& name, const MeshDesc& mesh);

}  // namespace mesh_file_detail

}  // namespace penumbra
