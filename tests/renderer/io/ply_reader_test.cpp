// The PLY reader: the three encodings read the same mesh, polygons are fan-triangulated, and
// malformed, truncated, lying or over-limit files are errors that name the file, found before
// anything is allocated from a count the file announces.
#include "renderer/io/ply_reader.h"

#include <gtest/gtest.h>

#include <limits>

#include "tests/renderer/io/mesh_file_test_util.h"

namespace penumbra::test {
namespace {

const std::string kName = "'bunny.ply'";

std::string ply_error(const std::string& bytes, const MeshFileLimits& limits = {}) {
  return mesh_file_error<parse_ply>(bytes, kName, limits);
}

// The triangles of sample_polygon_mesh(): fans from each face's first corner.
const std::vector<uint32_t> kFanIndices = {0, 1, 2, 0, 2, 3,            // quad
                                           1, 4, 2,                     // triangle
                                           4, 5, 6, 4, 6, 7, 4, 7, 2};  // pentagon

void expect_sample_mesh(const MeshFile& file) {
  const PolygonMesh m = sample_polygon_mesh();
  EXPECT_EQ(file.mesh.positions, m.positions);
  EXPECT_EQ(file.mesh.normals, m.normals);
  EXPECT_EQ(file.mesh.uvs, m.uvs);
  EXPECT_EQ(file.mesh.indices, kFanIndices);
  EXPECT_EQ(file.faces, 3);
}

TEST(PlyReader, AsciiLittleAndBigEndianReadTheSameMesh) {
  for (PlyEncoding e : {PlyEncoding::kAscii, PlyEncoding::kLittleEndian, PlyEncoding::kBigEndian}) {
    SCOPED_TRACE(int(e));
    PlyOptions o;
    o.encoding = e;
    expect_sample_mesh(parse_ply(write_ply(sample_polygon_mesh(), o), kName));
    // Other widths of the same values: double positions, uint indices, ushort counts.
    o.position_type = "double";
    o.index_type = "uint";
    o.count_type = "ushort";
    expect_sample_mesh(parse_ply(write_ply(sample_polygon_mesh(), o), kName));
  }
}

TEST(PlyReader, EveryUvNameVariant) {
  for (const auto& [u, v] : std::vector<std::pair<std::string, std::string>>{
           {"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}) {
    SCOPED_TRACE(u);
    PlyOptions o;
    o.encoding = PlyEncoding::kLittleEndian;
    o.u_name = u;
    o.v_name = v;
    EXPECT_EQ(parse_ply(write_ply(sample_polygon_mesh(), o), kName).mesh.uvs,
              sample_polygon_mesh().uvs);
  }
  PlyOptions half;
  half.u_name = "u";
  half.v_name = "q";
  EXPECT_CONTAINS(ply_error(write_ply(sample_polygon_mesh(), half)), "uvs need both 'u' and 'v'");
}

TEST(PlyReader, NormalsAndUvsAreOptional) {
  PolygonMesh m = sample_polygon_mesh();
  m.normals.clear();
  m.uvs.clear();
  const MeshFile file = parse_ply(write_ply(m, {PlyEncoding::kBigEndian}), kName);
  EXPECT_EQ(file.mesh.positions, m.positions);
  EXPECT_TRUE(file.mesh.normals.empty());
  EXPECT_TRUE(file.mesh.uvs.empty());
  EXPECT_EQ(file.mesh.indices, kFanIndices);
}

TEST(PlyReader, OtherPropertiesAndElementsAreSkipped) {
  // Vertex colours between the coordinates, a face property before the list, an edge element
  // with a list, in ASCII and binary.
  const std::string ascii =
      "ply\nformat ascii 1.0\nobj_info from a scanner\n"
      "element vertex 3\nproperty float x\nproperty uchar red\nproperty float y\nproperty float z\n"
      "property list uchar int ring\n"
      "element face 1\nproperty uchar flags\nproperty list uchar uint vertex_index\n"
      "element edge 2\nproperty list int int ends\nproperty float crease\n"
      "end_header\n"
      "0 255 0 0 2 7 8\n1 0 0 0 0\n0 10 1 0 1 3\n"
      "9 3 0 1 2\n"
      "2 0 1 0.5\n2 1 2 0\n";
  const MeshFile file = parse_ply(ascii, kName);
  EXPECT_EQ(file.mesh.positions, (std::vector<vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  EXPECT_EQ(file.mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(PlyReader, WindowsLineEndingsInTheHeader) {
  std::string bytes = write_ply(sample_polygon_mesh(), {PlyEncoding::kLittleEndian});
  const size_t data = bytes.find("end_header\n") + 11;
  std::string header = bytes.substr(0, data), crlf;
  for (char c : header) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  expect_sample_mesh(parse_ply(crlf + bytes.substr(data), kName));
}

TEST(PlyReader, TruncatedFilesAreErrors) {
  for (PlyEncoding e : {PlyEncoding::kAscii, PlyEncoding::kLittleEndian, PlyEncoding::kBigEndian}) {
    SCOPED_TRACE(int(e));
    const std::string bytes = write_ply(sample_polygon_mesh(), {e});
    const size_t data = bytes.find("end_header\n") + 11;
    // Every cut inside the data: nothing is read past the end, and the error says so.
    for (size_t cut = data; cut < bytes.size(); ++cut) {
      const std::string error = ply_error(bytes.substr(0, cut));
      // An ASCII cut inside a number leaves a shorter number (read, until a value is missing)
      // or no number at all ("-").
      if (e == PlyEncoding::kAscii && error.empty()) continue;
      EXPECT_TRUE(error.find("truncated") != std::string::npos ||
                  error.find("more than the") != std::string::npos ||
                  (e == PlyEncoding::kAscii && error.find("is not a number") != std::string::npos))
          << "cut at " << cut << ": " << error;
    }
    EXPECT_CONTAINS(ply_error(bytes.substr(0, data - 5)), "does not end");
  }
}

TEST(PlyReader, CountsThatLieFailBeforeAllocating) {
  // A tiny file announcing 2^40 faces, or vertices, or a 2^31-corner face. With limits that would
  // allow them, the only thing that can stop an allocation of terabytes is the check against the
  // bytes present: std::bad_alloc (or a crash) fails the test.
  MeshFileLimits huge;
  huge.max_triangles = int64_t(1) << 50;
  huge.max_vertices = std::numeric_limits<uint32_t>::max();
  for (PlyEncoding e : {PlyEncoding::kAscii, PlyEncoding::kLittleEndian}) {
    SCOPED_TRACE(int(e));
    std::string bytes = write_ply(sample_polygon_mesh(), {e});
    std::string faces = bytes;
    faces.replace(faces.find("element face 3"), 14, "element face 1099511627776");
    EXPECT_CONTAINS(ply_error(faces, huge),
                    "announces 1099511627776 'face' elements, more than the");
    std::string vertices = bytes;
    vertices.replace(vertices.find("element vertex 8"), 16, "element vertex 4000000000");
    EXPECT_CONTAINS(ply_error(vertices, huge), "announces 4000000000 'vertex' elements");
  }
  PolygonMesh m = sample_polygon_mesh();
  m.faces[2] = {4, 5, 6};
  PlyOptions o{PlyEncoding::kLittleEndian};
  o.count_type = "uint";
  std::string bytes = write_ply(m, o);
  // The last face's count, 3 as a little-endian uint 13 bytes from the end, becomes 2^31.
  const size_t count_at = bytes.size() - 16;
  ASSERT_EQ(bytes[count_at], 3);
  const uint32_t lie = uint32_t(1) << 31;
  std::memcpy(&bytes[count_at], &lie, 4);
  EXPECT_CONTAINS(ply_error(bytes, huge), "truncated");
}

TEST(PlyReader, IndicesOutOfRangeAndShortFaces) {
  PolygonMesh m = sample_polygon_mesh();
  m.faces[1] = {1, 8, 2};
  EXPECT_CONTAINS(ply_error(write_ply(m)),
                  "face 2: vertex index 8 is out of range (the file has 8 vertices)");
  m.faces[1] = {1, -1, 2};
  EXPECT_CONTAINS(ply_error(write_ply(m, {PlyEncoding::kBigEndian})),
                  "face 2: vertex index -1 is out of range");
  m.faces[1] = {1, 2};
  EXPECT_CONTAINS(ply_error(write_ply(m, {PlyEncoding::kLittleEndian})),
                  "face 2 has 2 vertices; a face needs at least 3");
  m.faces[1] = {};
  EXPECT_CONTAINS(ply_error(write_ply(m)), "face 2 has 0 vertices");
}

TEST(PlyReader, NonFiniteNumbersAreErrors) {
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  for (PlyEncoding e : {PlyEncoding::kAscii, PlyEncoding::kLittleEndian}) {
    SCOPED_TRACE(int(e));
    PolygonMesh m = sample_polygon_mesh();
    m.positions[3].y = nan;
    EXPECT_CONTAINS(ply_error(write_ply(m, {e})), "vertex 4: the position is not finite");
    m = sample_polygon_mesh();
    m.normals[5].z = -inf;
    EXPECT_CONTAINS(ply_error(write_ply(m, {e})), "vertex 6: the normal is not finite");
    m = sample_polygon_mesh();
    m.uvs[0].x = inf;
    EXPECT_CONTAINS(ply_error(write_ply(m, {e})), "vertex 1: the uv is not finite");
  }
  // A double beyond float's range cannot be placed in single precision.
  std::string bytes = write_ply(sample_polygon_mesh(), {PlyEncoding::kAscii, "double"});
  bytes.replace(bytes.find("\n0 0 0 ") + 1, 1, "1e300");
  EXPECT_CONTAINS(ply_error(bytes), "vertex 1: the position is not finite in single precision");
}

TEST(PlyReader, MalformedHeadersAndValues) {
  const std::string good = write_ply(sample_polygon_mesh());
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_CONTAINS(ply_error(""), "not a PLY file");
  EXPECT_CONTAINS(ply_error("solid cube\n"), "not a PLY file");
  EXPECT_CONTAINS(ply_error(with("format ascii 1.0", "format ascii 2.0")),
                  "header line 2: expected 'format <kind> 1.0'");
  EXPECT_CONTAINS(ply_error(with("format ascii 1.0", "format utf8 1.0")), "unknown format 'utf8'");
  EXPECT_CONTAINS(ply_error(with("format ascii 1.0\n", "")), "has no 'format' line");
  EXPECT_CONTAINS(ply_error(with("property float x", "property float w")), "has no property 'x'");
  EXPECT_CONTAINS(ply_error(with("property float nz\n", "")), "need all of nx, ny and nz");
  EXPECT_CONTAINS(ply_error(with("property float y", "property half y")),
                  "unknown property type 'half'");
  EXPECT_CONTAINS(ply_error(with("property float y", "property float x")),
                  "property 'x' appears twice");
  EXPECT_CONTAINS(ply_error(with("vertex_indices", "corners")), "has no 'vertex_indices' list");
  EXPECT_CONTAINS(ply_error(with("list uchar int", "list float int")),
                  "expected 'property list <integer type>");
  EXPECT_CONTAINS(ply_error(with("list uchar int", "list uchar float")),
                  "must be a list of integers");
  EXPECT_CONTAINS(ply_error(with("element face 3", "element facet 3")), "has no face element");
  EXPECT_CONTAINS(ply_error(with("element face 3", "element face -3")), "a count of 0 or more");
  EXPECT_CONTAINS(ply_error(with("comment written", "commentary written")),
                  "unknown keyword 'commentary'");
  EXPECT_CONTAINS(ply_error(with("\n0 0 0 ", "\n0 zero 0 ")),
                  "'vertex' 1 of 8, 'zero' is not a number");
  EXPECT_CONTAINS(ply_error(with("\n4 0 1 2 3", "\n4.5 0 1 2 3")),
                  "4.5 is not a value of the property's integer type");
  EXPECT_CONTAINS(ply_error(with("\n4 0 1 2 3", "\n300 0 1 2 3")), "300 is not a value");
}

TEST(PlyReader, LimitsOnVerticesTrianglesAndBytes) {
  const std::string bytes = write_ply(sample_polygon_mesh(), {PlyEncoding::kLittleEndian});
  MeshFileLimits limits;
  limits.max_vertices = 8;
  limits.max_triangles = 6;  // exactly what the mesh has: accepted
  EXPECT_EQ(ply_error(bytes, limits), "");
  limits.max_vertices = 7;
  EXPECT_CONTAINS(ply_error(bytes, limits), "announces 8 vertices; at most 7 are allowed");
  limits.max_vertices = 8;
  limits.max_triangles = 5;  // the pentagon's third triangle is one too many
  EXPECT_CONTAINS(ply_error(bytes, limits), "face 3 takes the mesh past the limit of 5 triangles");
  limits.max_triangles = 2;  // fewer than the faces: refused from the header
  EXPECT_CONTAINS(ply_error(bytes, limits), "announces 3 faces; at most 2 triangles");
  limits.max_triangles = 6;
  limits.max_file_bytes = int64_t(bytes.size()) - 1;
  EXPECT_CONTAINS(ply_error(bytes, limits), "bytes; at most");
}

}  // namespace
}  // namespace penumbra::test
