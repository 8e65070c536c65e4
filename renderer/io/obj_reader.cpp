#include "renderer/io/obj_reader.h"

#include <tiny_obj_loader.h>

#include <limits>
#include <streambuf>
#include <unordered_map>

namespace penumbra {
namespace {

using mesh_file_detail::fail;

// ---- Screening -------------------------------------------------------------------------------
//
// tinyobjloader allocates from what it reads without limits, and some statements amplify: a
// 20-byte `t` (subdivision tag) line makes it allocate 8192 ints, floats and strings (~330 KB),
// `g`/`o` lines copy whole shapes, `l`/`p` lines build their own index lists, `mtllib` opens
// another file by any path. It stores a face's corner count in an unsigned char (a 256-gon reads
// back as 0 corners), reads indices with atoi and a number's decimal exponent into an int
// (both undefined beyond int: "1e99999999999" overflows). So before it sees the
// bytes, every line goes through the same line and statement rules tinyobjloader uses
// (safeGetline: '\n', '\r' or "\r\n" ends a line; leading spaces and tabs skipped; a keyword is
// followed by a space or tab), and
//  - a line that is not v, vn, vt or f becomes a comment ('#' written over its first character);
//  - v, vn, vt lines and faces are counted, and each face's corners (the runs of characters other
//    than space, tab and '\r', which is how tinyobjloader splits them) recorded;
//  - every digit run of a face and every exponent of a v, vn or vt line must fit an int;
//  - the counts are held to the limits: then tinyobjloader's memory is a small multiple of them.

struct Screened {
  uint64_t positions = 0, normals = 0, uvs = 0;
  std::vector<uint32_t> face_corners;  // per face, in file order
};

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// Steps over the digit run at p; false if its value does not fit an int.
bool skip_int_digits(const char*& p, const char* end) {
  uint64_t value = 0;
  for (; p < end && *p >= '0' && *p <= '9'; ++p) {
    value = value * 10 + uint64_t(*p - '0');
    if (value > uint64_t(std::numeric_limits<int>::max())) return false;
  }
  return true;
}

// Counts a face's corners and checks that every number in it fits an int (tinyobjloader reads
// them with atoi).
uint64_t face_corners(const char* p, const char* end, uint64_t line, const std::string& name) {
  uint64_t corners = 0;
  bool in_corner = false;
  while (p < end && *p != '\0') {
    const bool separator = is_blank(*p) || *p == '\r';
    if (!separator && !in_corner) ++corners;
    in_corner = !separator;
    if (*p >= '0' && *p <= '9') {
      if (!skip_int_digits(p, end))
        fail(name, "line " + std::to_string(line) + ": a face index is too large");
    } else {
      ++p;
    }
  }
  return corners;
}

// Checks that every exponent on a v, vn or vt line fits an int. tinyobjloader's number parser
// accumulates the digits after 'e' or 'E' (and an optional sign) in an int; an 'e' right after a
// digit or '.' is where it can get there. Any other 'e' is not a number to it, so stricter is
// harmless.
void check_exponents(const char* p, const char* end, uint64_t line, const std::string& name) {
  for (const char* begin = p; p < end && *p != '\0'; ++p) {
    if ((*p != 'e' && *p != 'E') || p == begin) continue;
    const char before = p[-1];
    if (!(before >= '0' && before <= '9') && before != '.') continue;
    const char* q = p + 1;
    if (q < end && (*q == '+' || *q == '-')) ++q;
    if (!skip_int_digits(q, end))
      fail(name, "line " + std::to_string(line) + ": a number's exponent is too large");
    p = q - 1;
  }
}

Screened screen(std::string& bytes, const std::string& name, const MeshFileLimits& limits) {
  Screened s;
  uint64_t triangles = 0;
  const uint64_t max_vertices = uint64_t(limits.max_vertices);
  char* const data = bytes.data();
  const size_t size = bytes.size();
  uint64_t line = 0;
  for (size_t begin = 0; begin < size;) {
    size_t end = begin;
    while (end < size && data[end] != '\n' && data[end] != '\r') ++end;
    ++line;
    size_t k = begin;
    while (k < end && is_blank(data[k])) ++k;
    const char c0 = k < end ? data[k] : '\0';
    const char c1 = k + 1 < end ? data[k + 1] : '\0';
    const char c2 = k + 2 < end ? data[k + 2] : '\0';
    if (c0 == 'v' && is_blank(c1)) {
      if (++s.positions > max_vertices)
        fail(name, "more than " + std::to_string(max_vertices) + " vertex positions (the limit)");
      check_exponents(data + k + 2, data + end, line, name);
    } else if (c0 == 'v' && c1 == 'n' && is_blank(c2)) {
      if (++s.normals > max_vertices)
        fail(name, "more than " + std::to_string(max_vertices) + " normals (the vertex limit)");
      check_exponents(data + k + 3, data + end, line, name);
    } else if (c0 == 'v' && c1 == 't' && is_blank(c2)) {
      if (++s.uvs > max_vertices)
        fail(name, "more than " + std::to_string(max_vertices) + " uvs (the vertex limit)");
      check_exponents(data + k + 3, data + end, line, name);
    } else if (c0 == 'f' && is_blank(c1)) {
      const uint64_t corners = face_corners(data + k + 2, data + end, line, name);
      if (corners < 3)
        fail(name, "line " + std::to_string(line) + ": a face needs at least 3 vertices");
      triangles += corners - 2;
      if (triangles > uint64_t(limits.max_triangles))
        fail(name, "line " + std::to_string(line) + ": more than " +
                       std::to_string(limits.max_triangles) + " triangles (the limit)");
      s.face_corners.push_back(uint32_t(corners));  // corners - 2 <= max_triangles
    } else if (c0 != '\0' && c0 != '#') {
      data[k] = '#';
    }
    // Past the line's end: '\n', or '\r' with the '\n' that may follow it.
    begin = end;
    if (begin < size && data[begin++] == '\r' && begin < size && data[begin] == '\n') ++begin;
  }
  if (s.face_corners.empty()) fail(name, "the file has no faces");
  return s;
}

// An istream over the screened bytes without copying them.
struct MemoryBuffer : std::streambuf {
  explicit MemoryBuffer(std::string& bytes) {
    setg(bytes.data(), bytes.data(), bytes.data() + bytes.size());
  }
};

// ---- Vertices --------------------------------------------------------------------------------

// OBJ indexes positions, normals and uvs separately; the renderer needs one index per vertex.
// Each corner's (position, normal, uv) triple becomes one output vertex, shared by the corners
// with the same triple. Most positions appear with one triple only, so the first is found
// through a per-position slot and only seams need the hash map.
class VertexMerger {
 public:
  VertexMerger(const tinyobj::attrib_t& attrib, bool normals, bool uvs, const std::string& name,
               const MeshFileLimits& limits, MeshDesc& mesh)
      : attrib_(attrib),
        normals_(normals),
        uvs_(uvs),
        name_(name),
        limits_(limits),
        mesh_(mesh),
        first_(attrib.vertices.size() / 3, kNone) {}

  uint32_t vertex(const tinyobj::index_t& corner, int64_t face) {
    const int64_t p = check(corner.vertex_index, attrib_.vertices.size() / 3, "vertex", face);
    const int64_t n =
        normals_ ? check(corner.normal_index, attrib_.normals.size() / 3, "normal", face) : -1;
    const int64_t t =
        uvs_ ? check(corner.texcoord_index, attrib_.texcoords.size() / 2, "uv", face) : -1;
    uint32_t& first = first_[size_t(p)];
    if (first == kNone) return first = add(p, n, t);
    if (key_of(first) == Key{p, n, t}) return first;
    const auto [it, inserted] = seams_.try_emplace(Key{p, n, t}, 0u);
    if (inserted) it->second = add(p, n, t);
    return it->second;
  }

 private:
  static constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  struct Key {
    int64_t p, n, t;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      const uint64_t h =
          uint64_t(k.p) * 0x9E3779B97F4A7C15ull ^ uint64_t(k.n) << 21 ^ uint64_t(k.t) << 42;
      return size_t(h ^ h >> 29);
    }
  };

  int64_t check(int index, size_t count, const char* what, int64_t face) const {
    if (index < 0 || size_t(index) >= count)
      fail(name_, "face " + std::to_string(face + 1) + ": a " + what +
                      " index is out of range (the file has " + std::to_string(count) + ")");
    return index;
  }

  Key key_of(uint32_t v) const { return sources_[v]; }

  uint32_t add(int64_t p, int64_t n, int64_t t) {
    if (int64_t(mesh_.positions.size()) >= std::min<int64_t>(limits_.max_vertices, kNone))
      fail(name_,
           "more than " + std::to_string(limits_.max_vertices) + " distinct vertices (the limit)");
    const auto& v = attrib_.vertices;
    mesh_.positions.emplace_back(v[3 * size_t(p)], v[3 * size_t(p) + 1], v[3 * size_t(p) + 2]);
    if (normals_) {
      const auto& vn = attrib_.normals;
      mesh_.normals.emplace_back(vn[3 * size_t(n)], vn[3 * size_t(n) + 1], vn[3 * size_t(n) + 2]);
    }
    if (uvs_) {
      const auto& vt = attrib_.texcoords;
      mesh_.uvs.emplace_back(vt[2 * size_t(t)], 1.f - vt[2 * size_t(t) + 1]);  // v flipped
    }
    sources_.push_back({p, n, t});
    return uint32_t(mesh_.positions.size() - 1);
  }

  const tinyobj::attrib_t& attrib_;
  bool normals_, uvs_;
  const std::string& name_;
  const MeshFileLimits& limits_;
  MeshDesc& mesh_;
  std::vector<uint32_t> first_;  // per position: the output vertex first made from it
  std::vector<Key> sources_;     // per output vertex
  std::unordered_map<Key, uint32_t, KeyHash> seams_;
};

}  // namespace

MeshFile parse_obj(std::string bytes, const std::string& name, const MeshFileLimits& limits) {
  if (int64_t(bytes.size()) > limits.max_file_bytes)
    fail(name, "the file has " + std::to_string(bytes.size()) + " bytes; at most " +
                   std::to_string(limits.max_file_bytes));
  const Screened screened = screen(bytes, name, limits);

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warnings, errors;
  {
    MemoryBuffer buffer(bytes);
    std::istream in(&buffer);
    // No material reader: mtllib is a comment by now anyway. No triangulation: tinyobjloader's
    // splits quads along the shorter diagonal and clips ears; the format promises a fan.
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warnings, &errors, &in, nullptr,
                          /*triangulate=*/false, /*default_vcols_fallback=*/false))
      fail(name, "cannot parse the file: " + errors.substr(0, errors.find('\n')));
  }
  std::string().swap(bytes);  // not needed any more: lower the peak

  // Which attributes every corner has; attributes on some corners only are dropped.
  // A corner naming a normal or uv the file lacks is reported by VertexMerger, not ignored.
  bool all_normals = true, all_uvs = true;
  bool some_normals = false, some_uvs = false;
  size_t corners = 0;
  for (const tinyobj::shape_t& shape : shapes)
    for (const tinyobj::index_t& c : shape.mesh.indices) {
      ++corners;
      all_normals &= c.normal_index >= 0;
      all_uvs &= c.texcoord_index >= 0;
      some_normals |= c.normal_index >= 0;
      some_uvs |= c.texcoord_index >= 0;
    }
  uint64_t expected = 0;
  for (uint32_t n : screened.face_corners) expected += n;
  if (corners != expected) fail(name, "the faces could not be read consistently");

  MeshFile out;
  if (some_normals && !all_normals)
    out.warnings.push_back(
        name + ": normals are given for some face corners only; the mesh is shaded flat");
  if (some_uvs && !all_uvs)
    out.warnings.push_back(name + ": uvs are given for some face corners only; they are ignored");
  out.faces = int64_t(screened.face_corners.size());
  VertexMerger merger(attrib, all_normals, all_uvs, name, limits, out.mesh);
  mesh_file_detail::FaceSink sink(name, limits, std::numeric_limits<uint32_t>::max(),
                                  out.mesh.indices);
  std::vector<int64_t> face_vertices;
  size_t face = 0;
  for (const tinyobj::shape_t& shape : shapes)
    for (size_t c = 0; c < shape.mesh.indices.size(); ++face) {
      // The screened count, not tinyobjloader's unsigned char one.
      if (face >= screened.face_corners.size() ||
          screened.face_corners[face] > shape.mesh.indices.size() - c)
        fail(name, "the faces could not be read consistently");
      const uint32_t n = screened.face_corners[face];
      face_vertices.resize(n);
      for (uint32_t k = 0; k < n; ++k, ++c)
        face_vertices[k] = merger.vertex(shape.mesh.indices[c], int64_t(face));
      sink.add(face_vertices.data(), n, int64_t(face));
    }
  mesh_file_detail::check_finite(name, out.mesh);
  return out;
}

}  // namespace penumbra
