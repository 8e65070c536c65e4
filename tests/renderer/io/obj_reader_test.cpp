// The OBJ reader: positions, normals and uvs (v flipped), polygons fanned from their first
// corner, statements other than v/vn/vt/f ignored, and malformed or hostile files as errors that
// name the file.
#include "renderer/io/obj_reader.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/renderer/io/mesh_file_test_util.h"

namespace penumbra::test {
namespace {

const std::string kName = "'teapot.obj'";

std::string obj_error(const std::string& bytes, const MeshFileLimits& limits = {}) {
  return mesh_file_error<parse_obj>(bytes, kName, limits);
}

const char* kQuadAndPentagon =
    "# a quad and a pentagon sharing an edge\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2.5 0.5 0\nv 2 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.25\n"
    "vn 0 0 1\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
    "f 2/2/1 5/5/1 6/5/1 7/5/1 3/3/1\n";

TEST(ObjReader, PositionsNormalsUvsAndFans) {
  const MeshFile file = parse_obj(kQuadAndPentagon, kName);
  const MeshDesc& m = file.mesh;
  EXPECT_EQ(file.faces, 2);
  // Vertices in order of first use; corners with the same (v, vt, vn) share one.
  EXPECT_EQ(
      m.positions,
      (std::vector<vec3>{
          {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2.5f, 0.5f, 0}, {2, 1, 0}}));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 6, 1, 6, 2}));
  EXPECT_EQ(m.normals, std::vector<vec3>(7, vec3(0, 0, 1)));
  // v flipped: OBJ's vt (s, t) becomes (s, 1 - t).
  EXPECT_EQ(m.uvs,
            (std::vector<vec2>{
                {0, 1}, {1, 1}, {1, 0}, {0, 0}, {0.5f, 0.75f}, {0.5f, 0.75f}, {0.5f, 0.75f}}));
  EXPECT_TRUE(file.warnings.empty());
}

TEST(ObjReader, SeamsSplitVerticesAndRelativeIndicesResolve) {
  // Positions 2 and 3 appear with two uvs each (seams): two vertices each. Negative indices count
  // back from the last element read so far.
  const MeshFile file = parse_obj(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
      "f 1/1 2/2 3/3\nf -3/3 -1/1 -2/2\n",
      kName);
  EXPECT_EQ(file.mesh.positions.size(), 6u);
  EXPECT_EQ(file.mesh.indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(file.mesh.positions[3], vec3(1, 0, 0));
  EXPECT_EQ(file.mesh.uvs[3], vec2(0, 0));  // vt 3 = (0, 1), flipped
  EXPECT_TRUE(file.mesh.normals.empty());
}

TEST(ObjReader, OtherStatementsAreIgnored) {
  // Materials, groups, smoothing, lines, points and subdivision tags: none changes the mesh, and
  // mtllib opens nothing (the named file does not exist; an absolute path would not be read).
  const std::string extras =
      "mtllib /etc/passwd\nmtllib missing.mtl\nusemtl red\ng group\no object\ns 1\n"
      "l 1 2\np 3\nt crease 8192/8192/8192 1 2\nvp 0.5\nvw 1 0 1.0\ncstype bezier\n";
  EXPECT_EQ(parse_obj(extras + kQuadAndPentagon, kName).mesh.indices,
            parse_obj(kQuadAndPentagon, kName).mesh.indices);
  // Statements the reader skips allocate nothing, however many (a tag line once cost ~330 KB).
  std::string tags;
  for (int i = 0; i < 20000; ++i) tags += "t a 8192/8192/8192\n";
  EXPECT_EQ(parse_obj(tags + kQuadAndPentagon, kName).faces, 2);
}

TEST(ObjReader, LineEndings) {
  std::string crlf, cr;
  for (char c : std::string(kQuadAndPentagon)) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  const MeshFile reference = parse_obj(kQuadAndPentagon, kName);
  EXPECT_EQ(parse_obj(crlf, kName).mesh.indices, reference.mesh.indices);
  EXPECT_EQ(parse_obj(cr, kName).mesh.indices, reference.mesh.indices);
  // A statement hidden behind a lone '\r' is still a statement of its own (screened as such).
  EXPECT_EQ(parse_obj(std::string("v 0 0 0\rt a 8192/8192/8192\n") + kQuadAndPentagon, kName).faces,
            2);
}

TEST(ObjReader, PolygonsWithMoreThan255Corners) {
  // A face's corner count is not kept in a byte (tinyobjloader, used until session 39, did).
  std::string obj;
  const int n = 300;
  for (int i = 0; i < n; ++i)
    obj += "v " + std::to_string(std::cos(6.283185 * i / n)) + " " +
           std::to_string(std::sin(6.283185 * i / n)) + " 0\n";
  obj += "f";
  for (int i = 1; i <= n; ++i) obj += " " + std::to_string(i);
  obj += "\nf 1 2 3\n";
  const MeshFile file = parse_obj(obj, kName);
  EXPECT_EQ(file.faces, 2);
  ASSERT_EQ(file.mesh.indices.size(), 3u * (n - 2 + 1));
  EXPECT_EQ(std::vector<uint32_t>(file.mesh.indices.end() - 6, file.mesh.indices.end()),
            (std::vector<uint32_t>{0, 298, 299, 0, 1, 2}));
}

TEST(ObjReader, AttributesOnSomeCornersOnlyAreDroppedWithAWarning) {
  const MeshFile file = parse_obj(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nf 1//1 2//1 3\nf 1/1 2/1 3/1\n", kName);
  EXPECT_TRUE(file.mesh.normals.empty());
  EXPECT_EQ(file.mesh.uvs.size(), 0u);
  ASSERT_EQ(file.warnings.size(), 2u);
  EXPECT_NE(file.warnings[0].find("normals are given for some face corners only"),
            std::string::npos);
  EXPECT_EQ(file.warnings[0].rfind(kName, 0), 0u);
}

TEST(ObjReader, BadIndicesAndFaces) {
  const std::string three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_CONTAINS(obj_error(three + "f 1 2 4\n"),
                  "face 1: a vertex index is out of range (the file has 3)");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 -4\n"), "face 1: a vertex index is out of range");
  EXPECT_CONTAINS(obj_error(three + "vn 0 0 1\nf 1//1 2//1 3//2\n"),
                  "face 1: a normal index is out of range");
  EXPECT_CONTAINS(obj_error(three + "f 1//1 2//1 3//1\n"),
                  "face 1: a normal index is out of range (the file has 0)");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 0\n"), "line 4: a face index is 0 (OBJ counts from 1)");
  EXPECT_CONTAINS(obj_error(three + "f 1 2/x 3\n"), "line 4: cannot read the face corner index 'x'");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 3/\n"), "line 4: a face corner has an empty index");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 3//\n"), "line 4: a face corner has an empty index");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 3/1/1/1\n"), "line 4: cannot read the face corner index '3/1/1/1'");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 -99999999999\n"), "line 4: a face index is too large");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 -\n"), "line 4: cannot read the face corner index '-'");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 3/ \n"), "line 4: a face corner has an empty index");
  // Signs are allowed: +3 is 3, -1 the last vertex read so far.
  EXPECT_EQ(parse_obj(three + "f 1 +2 -1\n", kName).mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_CONTAINS(obj_error(three + "f 1 2\n"), "line 4: a face needs at least 3 vertices");
  EXPECT_CONTAINS(obj_error(three + "f\tx\n"), "line 4: cannot read the face corner index 'x'");
  EXPECT_CONTAINS(obj_error(three + "f 1 2 99999999999\n"), "line 4: a face index is too large");
  EXPECT_CONTAINS(obj_error(three), "the file has no faces");
  EXPECT_CONTAINS(obj_error(""), "the file has no faces");
}

TEST(ObjReader, NonFiniteNumbersAreErrors) {
  EXPECT_CONTAINS(obj_error("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"),
                  "vertex 2: the position is not finite");
  EXPECT_CONTAINS(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1e99\nf 1//1 2//1 3//1\n"),
                  "the normal is not finite");
}

// Numbers are read with std::from_chars: any exponent, the result rounded to a float (beyond its
// range: infinite, reported by check_finite with the element; below it: zero). A token that is
// not a number is an error naming the line, never a silent 0.
TEST(ObjReader, NumbersOfAnyExponentAndMalformedNumbers) {
  const std::string rest = "v 1 0 0\nv 0 1 0\nf 1 2 3\n";
  EXPECT_CONTAINS(obj_error("v 0 0 2.5e99999999999\n" + rest),
                  "vertex 1: the position is not finite");
  EXPECT_CONTAINS(obj_error("v 0 0 -1e39\n" + rest), "vertex 1: the position is not finite");
  EXPECT_CONTAINS(obj_error("v 0 nan 0\n" + rest), "vertex 1: the position is not finite");
  EXPECT_EQ(obj_error("v 0 0 1e-0000000000000000000038\n" + rest), "");
  EXPECT_EQ(parse_obj("v 0 0 1e-99999999999\n" + rest, kName).mesh.positions[0], vec3(0, 0, 0));
  // Below float's normal range: the subnormal nearest (through double), or a signed zero.
  EXPECT_EQ(parse_obj("v 1e-40 -1e-50 0\n" + rest, kName).mesh.positions[0],
            vec3(float(1e-40), -0.f, 0));
  EXPECT_TRUE(std::signbit(parse_obj("v 0 -1e-50 0\n" + rest, kName).mesh.positions[0].y));
  EXPECT_CONTAINS(obj_error("v 0 0 -1e400\n" + rest), "vertex 1: the position is not finite");
  // v's w (or a vertex colour) and anything after it are not read; missing coordinates are 0.
  EXPECT_EQ(obj_error("v 0 0 0 e99999999999\n" + rest), "");
  EXPECT_EQ(parse_obj("v 0.5 +2\n" + rest, kName).mesh.positions[0], vec3(0.5f, 2, 0));
  EXPECT_CONTAINS(obj_error("v 0 0 1x\n" + rest), "line 1: cannot read '1x' as a number");
  EXPECT_CONTAINS(obj_error("v 0 0 0\n" + rest + "vn 0 0 one\n"),
                  "line 5: cannot read 'one' as a number");
  EXPECT_CONTAINS(obj_error("v 0 0 0\n" + rest + "vt 0 --1\n"), "line 5: cannot read '--1' as a number");
}

// Large files are read in parts on several threads: any split gives the one-piece mesh, relative
// indices reaching back into earlier parts included, and an error names the line in the file.
TEST(ObjReader, PartsGiveTheWholeFilesMesh) {
  std::string obj = "# a strip of quads, relative and absolute indices, three line-end styles\r\n";
  const int n = 40;
  for (int i = 0; i <= n; ++i) {
    obj += "v " + std::to_string(i) + " 0 0\nv " + std::to_string(i) + " 1 0.5\r";
    obj += "vt " + std::to_string(i / double(n)) + " 0\r\nvt " + std::to_string(i / double(n)) + " 1\n";
    obj += "vn 0 0 1\n";
    if (i > 0) {
      // This quad by negative indices (counting back over the last two columns), the next
      // statement groups by absolute ones.
      obj += (i % 2 ? "f -4/-4/-1 -2/-2/-1 -1/-1/-1 -3/-3/-1\n" : "g strip\nf ") +
             (i % 2 ? std::string()
                    : std::to_string(2 * i - 1) + "/" + std::to_string(2 * i - 1) + "/" + std::to_string(i) + " " +
                          std::to_string(2 * i + 1) + "/" + std::to_string(2 * i + 1) + "/" + std::to_string(i + 1) + " " +
                          std::to_string(2 * i + 2) + "/" + std::to_string(2 * i + 2) + "/" + std::to_string(i + 1) + " " +
                          std::to_string(2 * i) + "/" + std::to_string(2 * i) + "/" + std::to_string(i) + "\n");
    }
  }
  const MeshFile whole = obj_reader_detail::parse_obj_in_parts(obj, kName, {}, 1);
  ASSERT_EQ(whole.faces, n);
  ASSERT_EQ(whole.mesh.indices.size(), size_t(6 * n));
  for (size_t parts : {2u, 3u, 5u, 16u, 97u, 4000u}) {
    SCOPED_TRACE(parts);
    const MeshFile split = obj_reader_detail::parse_obj_in_parts(obj, kName, {}, parts);
    EXPECT_EQ(split.faces, whole.faces);
    EXPECT_EQ(split.mesh.positions, whole.mesh.positions);
    EXPECT_EQ(split.mesh.normals, whole.mesh.normals);
    EXPECT_EQ(split.mesh.uvs, whole.mesh.uvs);
    EXPECT_EQ(split.mesh.indices, whole.mesh.indices);
    // An error near the end names its line in the whole file; a relative index before the
    // first vertex is out of range however the file is split.
    EXPECT_CONTAINS(obj_error(obj + "v 1 2 x\n"),
                    "line " + std::to_string(5 * (n + 1) + n + n / 2 + 2) + ": cannot read 'x'");
    const std::string error = [&] {
      try {
        obj_reader_detail::parse_obj_in_parts(obj + "v 1 2 x\n", kName, {}, parts);
      } catch (const MeshFileError& e) {
        return std::string(e.what());
      }
      return std::string();
    }();
    EXPECT_EQ(error, obj_error(obj + "v 1 2 x\n"));
  }
  // The limits hold for the parts together.
  MeshFileLimits limits;
  limits.max_vertices = 2 * (n + 1) - 1;
  for (size_t parts : {1u, 4u})
    try {
      obj_reader_detail::parse_obj_in_parts(obj, kName, limits, parts);
      ADD_FAILURE() << parts;
    } catch (const MeshFileError& e) {
      EXPECT_NE(std::string(e.what()).find("more than 81 vertex positions (the limit)"), std::string::npos);
    }
}

TEST(ObjReader, Limits) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  MeshFileLimits limits;
  limits.max_vertices = 4;
  limits.max_triangles = 2;
  EXPECT_EQ(obj_error(quad, limits), "");
  limits.max_triangles = 1;
  EXPECT_CONTAINS(obj_error(quad, limits), "line 5: more than 1 triangles (the limit)");
  limits.max_triangles = 2;
  limits.max_vertices = 3;
  EXPECT_CONTAINS(obj_error(quad, limits), "more than 3 vertex positions (the limit)");
  limits.max_vertices = 4;
  limits.max_file_bytes = int64_t(quad.size()) - 1;
  EXPECT_CONTAINS(obj_error(quad, limits), "bytes; at most");
}

}  // namespace
}  // namespace penumbra::test
