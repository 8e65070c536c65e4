#pragma once
// Helpers of the mesh-file tests: PLY files written the way a test asks (the same polygon mesh in
// ASCII, binary little- or big-endian, with chosen property names and types), and the errors
// of a reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/io/mesh_file.h"

namespace penumbra::test {

enum class PlyEncoding { kAscii, kLittleEndian, kBigEndian };

struct PolygonMesh {
  std::vector<vec3> positions;
  std::vector<vec3> normals;  // empty or one per position
  std::vector<vec2> uvs;      // empty or one per position
  std::vector<std::vector<int64_t>> faces;
};

struct PlyOptions {
  PlyOptions() = default;
  PlyOptions(PlyEncoding e, std::string position = "float")
      : encoding(e), position_type(std::move(position)) {}

  PlyEncoding encoding = PlyEncoding::kAscii;
  std::string position_type = "float";
  std::string u_name = "u", v_name = "v";
  std::string count_type = "uchar", index_type = "int";
};

// A quad, a triangle and a pentagon over 8 vertices with normals and uvs; every number is exact
// in float, so any encoding reads back to the same values.
inline PolygonMesh sample_polygon_mesh() {
  PolygonMesh m;
  m.positions = {{0, 0, 0},    {1, 0, 0},     {1, 1, 0},    {0, 1, 0},
                 {2, 0, 0.5f}, {3, 0.25f, 0}, {3.5f, 1, 0}, {2.5f, 1.5f, -0.25f}};
  for (size_t i = 0; i < m.positions.size(); ++i) {
    m.normals.push_back(
        glm::normalize(vec3(0.f, 0.f, 1.f) + 0.125f * vec3(float(i % 3), 0.f, 0.f)));
    m.uvs.push_back(vec2(0.125f * float(i), 1.f - 0.0625f * float(i)));
  }
  m.faces = {{0, 1, 2, 3}, {1, 4, 2}, {4, 5, 6, 7, 2}};
  return m;
}

inline void append_value(std::string& out, const std::string& type, double v, PlyEncoding e) {
  if (e == PlyEncoding::kAscii) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g ", v);
    out += buf;
    return;
  }
  unsigned char raw[8];
  size_t n = 0;
  auto put = [&](auto x) {
    std::memcpy(raw, &x, sizeof x);
    n = sizeof x;
  };
  if (type == "char")
    put(int8_t(v));
  else if (type == "uchar")
    put(uint8_t(v));
  else if (type == "short")
    put(int16_t(v));
  else if (type == "ushort")
    put(uint16_t(v));
  else if (type == "int")
    put(int32_t(v));
  else if (type == "uint")
    put(uint32_t(v));
  else if (type == "float")
    put(float(v));
  else
    put(double(v));
  if (e == PlyEncoding::kBigEndian) std::reverse(raw, raw + n);
  out.append(reinterpret_cast<const char*>(raw), n);
}

inline std::string write_ply(const PolygonMesh& m, const PlyOptions& o = {}) {
  const char* format = o.encoding == PlyEncoding::kAscii          ? "ascii"
                       : o.encoding == PlyEncoding::kLittleEndian ? "binary_little_endian"
                                                                  : "binary_big_endian";
  std::string out = std::string("ply\nformat ") + format + " 1.0\ncomment written by the tests\n";
  out += "element vertex " + std::to_string(m.positions.size()) + "\n";
  for (const char* axis : {"x", "y", "z"}) out += "property " + o.position_type + " " + axis + "\n";
  if (!m.normals.empty()) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (!m.uvs.empty()) out += "property float " + o.u_name + "\nproperty float " + o.v_name + "\n";
  out += "element face " + std::to_string(m.faces.size()) + "\n";
  out += "property list " + o.count_type + " " + o.index_type + " vertex_indices\n";
  out += "end_header\n";
  const bool ascii = o.encoding == PlyEncoding::kAscii;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) append_value(out, o.position_type, m.positions[i][k], o.encoding);
    if (!m.normals.empty())
      for (int k = 0; k < 3; ++k) append_value(out, "float", m.normals[i][k], o.encoding);
    if (!m.uvs.empty())
      for (int k = 0; k < 2; ++k) append_value(out, "float", m.uvs[i][k], o.encoding);
    if (ascii) out += "\n";
  }
  for (const auto& face : m.faces) {
    append_value(out, o.count_type, double(face.size()), o.encoding);
    for (int64_t index : face) append_value(out, o.index_type, double(index), o.encoding);
    if (ascii) out += "\n";
  }
  return out;
}

// The message of the MeshFileError `Parse(bytes, name, limits)` throws, or "" if it succeeds.
// Every message must begin with the file's name. Any other exception (std::bad_alloc from an
// allocation sized by the file) escapes and fails the test.
template <auto Parse>
std::string mesh_file_error(const std::string& bytes, const std::string& name,
                            const MeshFileLimits& limits) {
  try {
    Parse(bytes, name, limits);
  } catch (const MeshFileError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(name + ": ", 0), 0u) << "the error must name the file: " << message;
    return message;
  }
  return "";
}

}  // namespace penumbra::test

#define EXPECT_CONTAINS(text, fragment)                            \
  do {                                                             \
    const std::string text_ = (text);                              \
    EXPECT_NE(text_.find(fragment), std::string::npos)             \
        << "expected '" << (fragment) << "' in '" << text_ << "'"; \
  } while (0)
