#include "renderer/io/mesh_file.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "renderer/io/file_bytes.h"
#include "renderer/io/obj_reader.h"
#include "renderer/io/ply_reader.h"

namespace penumbra {

namespace mesh_file_detail {

void fail(const std::string& name, const std::string& reason) {
  throw MeshFileError(name + ": " + reason);
}

void FaceSink::check(uint64_t count, int64_t face) const {
  if (count < 3)
    fail(name_, "face " + std::to_string(face + 1) + " has " + std::to_string(count) +
                    " vertices; a face needs at least 3");
  if (count - 2 > uint64_t(limits_.max_triangles - triangles_))
    fail(name_, "face " + std::to_string(face + 1) + " takes the mesh past the limit of " +
                    std::to_string(limits_.max_triangles) + " triangles");
}

void FaceSink::add(const int64_t* corners, uint64_t count, int64_t face) {
  check(count, face);
  for (uint64_t i = 0; i < count; ++i)
    if (corners[i] < 0 || uint64_t(corners[i]) >= vertex_count_)
      fail(name_, "face " + std::to_string(face + 1) + ": vertex index " +
                      std::to_string(corners[i]) + " is out of range (the file has " +
                      std::to_string(vertex_count_) + " vertices)");
  // A fan from the first corner: the same triangles for a convex polygon as any other
  // triangulation, and predictable (the scene format promises it) for the rest.
  for (uint64_t i = 1; i + 1 < count; ++i)
    indices_.insert(indices_.end(),
                    {uint32_t(corners[0]), uint32_t(corners[i]), uint32_t(corners[i + 1])});
  triangles_ += int64_t(count - 2);
}

void check_finite(const std::string& name, const MeshDesc& mesh) {
  auto finite = [](const auto& v) {
    for (int k = 0; k < v.length(); ++k)
      if (!std::isfinite(v[k])) return false;
    return true;
  };
  auto check = [&](const auto& values, const char* what) {
    const auto bad = std::find_if_not(values.begin(), values.end(), finite);
    if (bad != values.end())
      fail(name, "vertex " + std::to_string(bad - values.begin() + 1) + ": the " + what +
                     " is not finite in single precision (NaN, infinite or beyond 3.4e38)");
  };
  check(mesh.positions, "position");
  check(mesh.normals, "normal");
  check(mesh.uvs, "uv");
}

}  // namespace mesh_file_detail

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

bool is_mesh_file_name(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".ply" || ext == ".obj";
}

MeshFile read_mesh_file(const std::filesystem::path& path, const std::string& name,
                        const MeshFileLimits& limits) {
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    mesh_file_detail::fail(name, "unknown mesh file type '" + ext + "': expected .ply or .obj");
  FileBytes bytes;
  try {
    bytes = FileBytes::map(path, limits.max_file_bytes);
  } catch (const FileBytesError& e) {
    mesh_file_detail::fail(name, e.what());
  }
  // A file that shrank while it was read, or whose pages could not be read from the disk (those
  // bytes read as zeros), is reported as such, whatever the parser made of the zeros.
  std::optional<MeshFile> out;
  try {
    out = ext == ".ply" ? parse_ply(bytes.view(), name, limits)
                        : parse_obj(std::move(bytes), name, limits);  // released when read
  } catch (const MeshFileError&) {
    if (bytes.intact()) throw;
  }
  if (!bytes.intact())
    mesh_file_detail::fail(name, "the file changed while it was read (or a part of it could not be read)");
  return std::move(*out);
}

}  // namespace penumbra
