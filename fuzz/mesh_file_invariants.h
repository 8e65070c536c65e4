#pragma once
// What every mesh a reader returns must satisfy, checked by the mesh-file fuzz targets: whole
// triangles, indices in range, attribute arrays empty or one per vertex, every number finite.
// A violation aborts, which libFuzzer reports as a crash with the input that caused it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "renderer/io/mesh_file.h"

namespace penumbra::fuzz {

// Small limits keep each input fast; the limits themselves are tested in tests/renderer/io.
inline MeshFileLimits fuzz_mesh_limits() {
  MeshFileLimits limits;
  limits.max_file_bytes = 1 << 20;
  limits.max_vertices = 100'000;
  limits.max_triangles = 100'000;
  return limits;
}

inline void check_mesh_file(const MeshFile& file, const MeshFileLimits& limits) {
  const MeshDesc& m = file.mesh;
  if (m.indices.empty() || m.indices.size() % 3 != 0) std::abort();
  if (int64_t(m.indices.size() / 3) > limits.max_triangles) std::abort();
  if (int64_t(m.positions.size()) > limits.max_vertices) std::abort();
  if (file.faces <= 0 || file.faces > int64_t(m.indices.size() / 3)) std::abort();
  for (uint32_t i : m.indices)
    if (i >= m.positions.size()) std::abort();
  if (!m.normals.empty() && m.normals.size() != m.positions.size()) std::abort();
  if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) std::abort();
  for (const vec3& p : m.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  for (const vec3& n : m.normals)
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) std::abort();
  for (const vec2& uv : m.uvs)
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) std::abort();
}

// One fuzz input through `Parse(bytes, name, limits)`: a mesh must satisfy check_mesh_file, an
// error must be a MeshFileError naming the file; anything else escapes or aborts.
template <auto Parse>
void fuzz_mesh_reader(const uint8_t* data, size_t size, const std::string& name) {
  const MeshFileLimits limits = fuzz_mesh_limits();
  try {
    check_mesh_file(Parse(std::string(reinterpret_cast<const char*>(data), size), name, limits),
                    limits);
  } catch (const MeshFileError& e) {
    if (std::string_view(e.what()).substr(0, name.size() + 2) != name + ": ") std::abort();
  }
}

}  // namespace penumbra::fuzz
