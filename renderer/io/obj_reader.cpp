#include "renderer/io/obj_reader.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <limits>
#include <optional>
#include <thread>
#include <unordered_map>

namespace penumbra {
namespace {

using mesh_file_detail::fail;

// ---- Statements ------------------------------------------------------------------------------
//
// One pass over the bytes reads the four statements a mesh needs and skips every other line
// (materials, groups, smoothing, lines, points, free-form geometry: no statement allocates or
// opens anything). A line ends at '\n', '\r' or "\r\n"; leading spaces and tabs are skipped; a
// keyword is followed by a space or tab. Numbers are read by std::from_chars (correctly rounded,
// no exponent limit: 1e99999 is infinite and reported by check_finite); a face index must fit an
// int. Every count is held to the limits as it grows, so memory follows the limits and the file.
//
// (Until session 39 Debian's tinyobjloader parsed these bytes behind a screening pass that
// re-implemented its tokenizer to keep hostile input away from it; the two passes took 2.6x
// Mitsuba 3's OBJ loader on a 1M-triangle file: docs/mesh-files.md.)

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// A corner's indices, 0-based: kAbsent where the corner names none. A negative index counts back
// from the elements read so far; the result may be out of range, which VertexMerger reports.
constexpr int32_t kAbsent = std::numeric_limits<int32_t>::min();
struct Corner {
  int32_t position, uv, normal;
};

struct Statements {
  std::vector<float> positions, normals, uvs;  // 3, 3 and 2 floats per element
  std::vector<Corner> corners;
  std::vector<uint32_t> face_corners;  // per face, in file order
  uint64_t triangles = 0;
  // Corners with a negative index, as (corner, which: 1 position, 2 uv, 4 normal): read from a
  // part of the file, such an index counted back from that part's elements only, and is moved
  // by the elements before the part when the parts are joined.
  std::vector<std::pair<uint64_t, uint32_t>> relative;
  uint64_t lines = 0;  // lines read
};

// An error at a line of the part being read (0: of no line), before it becomes a MeshFileError
// with the line's number in the whole file.
struct LineError {
  uint64_t line;
  std::string reason;
};

// The statements of the bytes [begin, end), which start at a line's start.
class StatementReader {
 public:
  StatementReader(const char* begin, const char* end, const MeshFileLimits& limits)
      : p_(begin), end_(end), limits_(limits) {}

  Statements read() {
    while (p_ < end_) {
      ++out_.lines;
      const char* const line_end = find_line_end();
      const char* k = p_;
      while (k < line_end && is_blank(*k)) ++k;
      const size_t n = size_t(line_end - k);
      if (n >= 2 && k[0] == 'v' && is_blank(k[1])) {
        count(out_.positions.size() / 3, "vertex positions (the limit)");
        numbers(k + 2, line_end, 3, out_.positions);
      } else if (n >= 3 && k[0] == 'v' && k[1] == 'n' && is_blank(k[2])) {
        count(out_.normals.size() / 3, "normals (the vertex limit)");
        numbers(k + 3, line_end, 3, out_.normals);
      } else if (n >= 3 && k[0] == 'v' && k[1] == 't' && is_blank(k[2])) {
        count(out_.uvs.size() / 2, "uvs (the vertex limit)");
        numbers(k + 3, line_end, 2, out_.uvs);
      } else if (n >= 2 && k[0] == 'f' && is_blank(k[1])) {
        face(k + 2, line_end);
      }
      p_ = past_line_end(line_end, end_);
    }
    return std::move(out_);
  }

  // Past a line's end at q: '\n', or '\r' with the '\n' that may follow it.
  static const char* past_line_end(const char* q, const char* end) {
    if (q < end && *q++ == '\r' && q < end && *q == '\n') ++q;
    return q;
  }

 private:
  const char* find_line_end() const {
    const char* q = p_;
    while (q < end_ && *q != '\n' && *q != '\r') ++q;
    return q;
  }

  [[noreturn]] void fail_line(std::string reason) const { throw LineError{out_.lines, std::move(reason)}; }

  // Throws unless one more element (of so_far) is within the vertex limit.
  void count(size_t so_far, const char* what) const {
    if (so_far + 1 > uint64_t(limits_.max_vertices))
      throw LineError{0, "more than " + std::to_string(limits_.max_vertices) + " " + what};
  }

  // `wanted` numbers of a v, vn or vt line: missing ones are 0 and any after them are ignored
  // (v's optional w or vertex colour, vt's w), as common readers do.
  void numbers(const char* q, const char* line_end, int wanted, std::vector<float>& out) const {
    for (int i = 0; i < wanted; ++i) {
      while (q < line_end && is_blank(*q)) ++q;
      const char* const begin = q;
      while (q < line_end && !is_blank(*q)) ++q;
      out.push_back(begin == q ? 0.f : number(begin, q));
    }
  }

  float number(const char* begin, const char* stop) const {
    const char* first = begin;
    if (first + 1 < stop && *first == '+' && first[1] != '-') ++first;  // from_chars takes no '+'
    float value = 0.f;
    const auto [ptr, ec] = std::from_chars(first, stop, value);
    if (ec == std::errc::result_out_of_range) return out_of_float_range(first, stop);
    if (ec != std::errc() || ptr != stop)
      fail_line("cannot read '" + std::string(begin, std::min(stop, begin + 32)) + "' as a number");
    return value;
  }

  // A number std::from_chars found outside float's range (or, for some, in its subnormal
  // range): through double, then rounded to float (infinite beyond it: check_finite names the
  // element; a subnormal or zero below it); beyond double too, infinite or zero by the exponent's
  // sign. No strtof: it reads the locale's decimal point.
  float out_of_float_range(const char* first, const char* stop) const {
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(first, stop, value);
    if (ec == std::errc() && ptr == stop) return float(value);
    if (ec != std::errc::result_out_of_range || ptr != stop)
      fail_line("cannot read '" + std::string(first, std::min(stop, first + 32)) + "' as a number");
    const char* e = first;
    while (e < stop && *e != 'e' && *e != 'E') ++e;
    const float magnitude = e + 1 < stop && e[1] == '-' ? 0.f : std::numeric_limits<float>::infinity();
    return *first == '-' ? -magnitude : magnitude;
  }

  // A corner's index at q, up to the next '/', blank or line end (q left there): 1-based, or
  // negative counting back from the `so_far` read (`relative` set). Digits by hand in the one
  // pass that finds the corner's end: a million-triangle file has nine million of them.
  int32_t index(const char*& q, const char* line_end, size_t so_far, bool* relative) const {
    const char* const begin = q;
    const bool negative = q < line_end && *q == '-';
    if (q < line_end && (*q == '-' || *q == '+')) ++q;
    int64_t value = 0;
    const char* const digits = q;
    for (; q < line_end && *q >= '0' && *q <= '9'; ++q) {
      value = value * 10 + (*q - '0');
      if (value > std::numeric_limits<int>::max()) value = int64_t(1) << 40;  // stays too large
    }
    if (q < line_end && *q != '/' && !is_blank(*q)) {
      while (q < line_end && *q != '/' && !is_blank(*q)) ++q;
      bad_index(begin, q);
    }
    if (q == begin) fail_line("a face corner has an empty index");
    if (q == digits) bad_index(begin, q);
    if (value > std::numeric_limits<int>::max()) fail_line("a face index is too large");
    if (value == 0) fail_line("a face index is 0 (OBJ counts from 1)");
    *relative |= negative;
    // so_far is within the vertex limit and value within int: the result fits an int32 above
    // kAbsent.
    return int32_t(negative ? int64_t(so_far) - value : value - 1);
  }
  [[noreturn]] void bad_index(const char* begin, const char* stop) const {
    fail_line("cannot read the face corner index '" + std::string(begin, std::min(stop, begin + 32)) +
              "'");
  }

  // A face: corners v, v/vt, v//vn or v/vt/vn. Its triangles are held to the limit corner by
  // corner, so a face of a hundred million corners stops at the limit, not at the end of memory.
  void face(const char* q, const char* line_end) {
    uint64_t n = 0;
    for (;;) {
      while (q < line_end && is_blank(*q)) ++q;
      if (q == line_end) break;
      if (++n >= 3 && out_.triangles + (n - 2) > uint64_t(limits_.max_triangles))
        fail_line("more than " + std::to_string(limits_.max_triangles) + " triangles (the limit)");
      const char* const corner = q;
      bool p_relative = false, t_relative = false, n_relative = false;
      Corner c{index(q, line_end, out_.positions.size() / 3, &p_relative), kAbsent, kAbsent};
      if (q < line_end && *q == '/') {
        ++q;
        if (q < line_end && *q != '/') c.uv = index(q, line_end, out_.uvs.size() / 2, &t_relative);
        if (q < line_end && *q == '/') {
          ++q;
          c.normal = index(q, line_end, out_.normals.size() / 3, &n_relative);
        } else if (c.uv == kAbsent) {
          fail_line("a face corner has an empty index");
        }
        if (q < line_end && *q == '/') {  // a fourth index
          while (q < line_end && !is_blank(*q)) ++q;
          bad_index(corner, q);
        }
      }
      if (p_relative || t_relative || n_relative)
        out_.relative.emplace_back(out_.corners.size(),
                                   uint32_t(p_relative) | uint32_t(t_relative) << 1 |
                                       uint32_t(n_relative) << 2);
      out_.corners.push_back(c);
    }
    if (n < 3) fail_line("a face needs at least 3 vertices");
    out_.triangles += n - 2;
    out_.face_corners.push_back(uint32_t(n));  // n - 2 <= max_triangles
  }

  const char* p_;
  const char* const end_;
  const MeshFileLimits& limits_;
  Statements out_;
};

// A part of a file read on threads has at least this many bytes (below it a thread costs more
// than it saves).
constexpr size_t kPartBytes = size_t(4) << 20;

// The whole file's statements: read in `parts` pieces split at line ends, on as many threads;
// the first part holds every part's elements (positions, normals, uvs), each part its faces.
// The same statements as one piece gives, and for a file with one error the same
// message (line numbers count from the file's start; with several errors, a limit exceeded only
// by the parts together is reported after the other errors).
std::vector<Statements> read_statements(std::string_view bytes, const std::string& name,
                                        const MeshFileLimits& limits, size_t parts) {
  const char* const data = bytes.data();
  const char* const end = data + bytes.size();
  std::vector<const char*> cut{data};
  for (size_t i = 1; i < parts; ++i) {
    const char* q = std::max(cut.back(), data + bytes.size() * i / parts);
    while (q < end && *q != '\n' && *q != '\r') ++q;
    cut.push_back(StatementReader::past_line_end(q, end));
  }
  cut.push_back(end);
  std::vector<Statements> read(parts);
  std::vector<std::optional<LineError>> errors(parts);
  const auto read_part = [&](size_t i) {
    try {
      read[i] = StatementReader(cut[i], cut[i + 1], limits).read();
    } catch (LineError& e) {
      errors[i] = std::move(e);
    }
  };
  // Threads only where the parts are large enough to pay for them (a small file in parts, as
  // the tests and the fuzzer read them, takes the same steps on this thread).
  if (bytes.size() >= kPartBytes * 2)
    tbb::parallel_for(size_t(0), parts, read_part);
  else
    for (size_t i = 0; i < parts; ++i) read_part(i);
  // The first error in the file, its line counted from the file's start (every part before it
  // was read whole).
  uint64_t lines = 0;
  for (size_t i = 0; i < parts; ++i) {
    if (errors[i]) {
      const LineError& e = *errors[i];
      fail(name, e.line ? "line " + std::to_string(lines + e.line) + ": " + e.reason : e.reason);
    }
    lines += read[i].lines;
  }
  // The limits over the whole file (each part held them alone), before the parts are joined.
  uint64_t sizes[4] = {0, 0, 0, 0};  // positions, normals, uvs, triangles
  for (const Statements& part : read) {
    sizes[0] += part.positions.size() / 3;
    sizes[1] += part.normals.size() / 3;
    sizes[2] += part.uvs.size() / 2;
    sizes[3] += part.triangles;
  }
  const uint64_t max_vertices = uint64_t(limits.max_vertices);
  if (sizes[0] > max_vertices)
    fail(name, "more than " + std::to_string(max_vertices) + " vertex positions (the limit)");
  if (sizes[1] > max_vertices)
    fail(name, "more than " + std::to_string(max_vertices) + " normals (the vertex limit)");
  if (sizes[2] > max_vertices)
    fail(name, "more than " + std::to_string(max_vertices) + " uvs (the vertex limit)");
  if (sizes[3] > uint64_t(limits.max_triangles))
    fail(name, "more than " + std::to_string(limits.max_triangles) + " triangles (the limit)");
  // The parts' elements joined in the first part, each part keeping its own faces (the merge
  // walks them in order; copying a million triangles' corners costs more than the reading).
  Statements& all = read[0];
  all.positions.reserve(3 * sizes[0]);
  all.normals.reserve(3 * sizes[1]);
  all.uvs.reserve(2 * sizes[2]);
  for (size_t i = 1; i < parts; ++i) {
    Statements& part = read[i];
    const int64_t base[3] = {int64_t(all.positions.size() / 3), int64_t(all.uvs.size() / 2),
                             int64_t(all.normals.size() / 3)};
    for (const auto& [corner, which] : part.relative) {
      // A negative index counted back from this part's elements: the earlier parts' come first.
      // (It stays at or above -INT_MAX: never kAbsent.)
      Corner& c = part.corners[corner];
      if (which & 1u) c.position = int32_t(int64_t(c.position) + base[0]);
      if (which & 2u) c.uv = int32_t(int64_t(c.uv) + base[1]);
      if (which & 4u) c.normal = int32_t(int64_t(c.normal) + base[2]);
    }
    all.positions.insert(all.positions.end(), part.positions.begin(), part.positions.end());
    all.normals.insert(all.normals.end(), part.normals.begin(), part.normals.end());
    all.uvs.insert(all.uvs.end(), part.uvs.begin(), part.uvs.end());
    all.triangles += part.triangles;
    std::vector<float>().swap(part.positions);  // lower the peak as the parts are joined
    std::vector<float>().swap(part.normals);
    std::vector<float>().swap(part.uvs);
  }
  if (std::all_of(read.begin(), read.end(), [](const Statements& p) { return p.face_corners.empty(); }))
    fail(name, "the file has no faces");
  return read;
}

// ---- Vertices --------------------------------------------------------------------------------

// OBJ indexes positions, normals and uvs separately; the renderer needs one index per vertex.
// Each corner's (position, normal, uv) triple becomes one output vertex, shared by the corners
// with the same triple. Most positions appear with one triple only, so the first is found
// through a per-position slot and only seams need the hash map.
class VertexMerger {
 public:
  VertexMerger(const Statements& attrib, bool normals, bool uvs, const std::string& name,
               const MeshFileLimits& limits, MeshDesc& mesh)
      : attrib_(attrib),
        normals_(normals),
        uvs_(uvs),
        name_(name),
        limits_(limits),
        mesh_(mesh),
        first_(attrib.positions.size() / 3, First{kNone, 0, 0}) {}

  uint32_t vertex(const Corner& corner, int64_t face) {
    const int64_t p = check(corner.position, attrib_.positions.size() / 3, "vertex", face);
    const int64_t n =
        normals_ ? check(corner.normal, attrib_.normals.size() / 3, "normal", face) : -1;
    const int64_t t = uvs_ ? check(corner.uv, attrib_.uvs.size() / 2, "uv", face) : -1;
    First& first = first_[size_t(p)];
    if (first.vertex == kNone) {
      first = {add(p, n, t), int32_t(n), int32_t(t)};
      return first.vertex;
    }
    if (first.normal == int32_t(n) && first.uv == int32_t(t)) return first.vertex;
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

  int64_t check(int64_t index, size_t count, const char* what, int64_t face) const {
    if (index < 0 || size_t(index) >= count)
      fail(name_, "face " + std::to_string(face + 1) + ": a " + what +
                      " index is out of range (the file has " + std::to_string(count) + ")");
    return index;
  }

  uint32_t add(int64_t p, int64_t n, int64_t t) {
    if (int64_t(mesh_.positions.size()) >= std::min<int64_t>(limits_.max_vertices, kNone))
      fail(name_,
           "more than " + std::to_string(limits_.max_vertices) + " distinct vertices (the limit)");
    const auto& v = attrib_.positions;
    mesh_.positions.emplace_back(v[3 * size_t(p)], v[3 * size_t(p) + 1], v[3 * size_t(p) + 2]);
    if (normals_) {
      const auto& vn = attrib_.normals;
      mesh_.normals.emplace_back(vn[3 * size_t(n)], vn[3 * size_t(n) + 1], vn[3 * size_t(n) + 2]);
    }
    if (uvs_) {
      const auto& vt = attrib_.uvs;
      mesh_.uvs.emplace_back(vt[2 * size_t(t)], 1.f - vt[2 * size_t(t) + 1]);  // v flipped
    }
    return uint32_t(mesh_.positions.size() - 1);
  }

  const Statements& attrib_;
  bool normals_, uvs_;
  const std::string& name_;
  const MeshFileLimits& limits_;
  MeshDesc& mesh_;
  // Per position: the output vertex first made from it and that vertex's normal and uv indices
  // (-1 where the mesh has none), side by side so the common case -- a corner repeating its
  // position's first triple -- reads one slot.
  struct First {
    uint32_t vertex;
    int32_t normal, uv;
  };
  std::vector<First> first_;
  std::unordered_map<Key, uint32_t, KeyHash> seams_;
};

}  // namespace

MeshFile parse_obj(FileBytes&& bytes, const std::string& name, const MeshFileLimits& limits) {
  const size_t parts = std::clamp<size_t>(bytes.view().size() / kPartBytes, 1,
                                          std::max(1u, std::thread::hardware_concurrency()));
  return obj_reader_detail::parse_obj_in_parts(std::move(bytes), name, limits, parts);
}

MeshFile obj_reader_detail::parse_obj_in_parts(FileBytes&& bytes, const std::string& name,
                                               const MeshFileLimits& limits, size_t parts) {
  if (int64_t(bytes.view().size()) > limits.max_file_bytes)
    fail(name, "the file has " + std::to_string(bytes.view().size()) + " bytes; at most " +
                   std::to_string(limits.max_file_bytes));
  const std::vector<Statements> parts_read =
      read_statements(bytes.view(), name, limits, std::max<size_t>(parts, 1));
  bytes.release();  // not needed any more: lower the peak
  const Statements& elements = parts_read.front();

  // Which attributes every corner has; attributes on some corners only are dropped.
  // A corner naming a normal or uv the file lacks is reported by VertexMerger, not ignored.
  bool all_normals = true, all_uvs = true;
  bool some_normals = false, some_uvs = false;
  uint64_t corners = 0, faces = 0;
  for (const Statements& part : parts_read) {
    for (const Corner& c : part.corners) {
      all_normals &= c.normal != kAbsent;
      all_uvs &= c.uv != kAbsent;
      some_normals |= c.normal != kAbsent;
      some_uvs |= c.uv != kAbsent;
    }
    corners += part.corners.size();
    faces += part.face_corners.size();
  }

  MeshFile out;
  if (some_normals && !all_normals)
    out.warnings.push_back(
        name + ": normals are given for some face corners only; the mesh is shaded flat");
  if (some_uvs && !all_uvs)
    out.warnings.push_back(name + ": uvs are given for some face corners only; they are ignored");
  out.faces = int64_t(faces);
  VertexMerger merger(elements, all_normals, all_uvs, name, limits, out.mesh);
  mesh_file_detail::FaceSink sink(name, limits, std::numeric_limits<uint32_t>::max(),
                                  out.mesh.indices);
  out.mesh.indices.reserve(3 * (corners - 2 * faces));
  std::vector<int64_t> face_vertices;
  int64_t face = 0;
  for (const Statements& part : parts_read) {
    size_t c = 0;
    for (const uint32_t n : part.face_corners) {
      face_vertices.resize(n);
      for (uint32_t k = 0; k < n; ++k, ++c) face_vertices[k] = merger.vertex(part.corners[c], face);
      sink.add(face_vertices.data(), n, face++);
    }
  }
  mesh_file_detail::check_finite(name, out.mesh);
  return out;
}

}  // namespace penumbra
