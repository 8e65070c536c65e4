#include "renderer/io/ply_reader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

namespace penumbra {
namespace {

using mesh_file_detail::fail;

enum class Type : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct TypeName {
  std::string_view name;  // the original name (ply.c) and the sized one (PLY 1.0 as Bourke lists)
  std::string_view sized;
  Type type;
};
constexpr std::array<TypeName, 8> kTypes = {{{"char", "int8", Type::kInt8},
                                             {"uchar", "uint8", Type::kUint8},
                                             {"short", "int16", Type::kInt16},
                                             {"ushort", "uint16", Type::kUint16},
                                             {"int", "int32", Type::kInt32},
                                             {"uint", "uint32", Type::kUint32},
                                             {"float", "float32", Type::kFloat32},
                                             {"double", "float64", Type::kFloat64}}};

constexpr int size_of(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

constexpr bool is_integer(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }

// The range an integer type holds, for checking ASCII values against their declared type.
std::pair<double, double> integer_range(Type t) {
  switch (t) {
    case Type::kInt8:
      return {-128.0, 127.0};
    case Type::kUint8:
      return {0.0, 255.0};
    case Type::kInt16:
      return {-32768.0, 32767.0};
    case Type::kUint16:
      return {0.0, 65535.0};
    case Type::kInt32:
      return {-2147483648.0, 2147483647.0};
    default:
      return {0.0, 4294967295.0};
  }
}

std::optional<Type> parse_type(std::string_view word) {
  for (const TypeName& t : kTypes)
    if (word == t.name || word == t.sized) return t.type;
  return std::nullopt;
}

struct Property {
  std::string name;
  Type type = Type::kFloat32;  // the item type for a list
  bool list = false;
  Type count_type = Type::kUint8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kBinaryLittle, kBinaryBig };

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  size_t data_begin = 0;
};

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Header text is user data: quote at most a few printable characters of it.
std::string shown(std::string_view word) {
  std::string out = "'";
  for (char c : word.substr(0, 40)) out += (c >= 32 && c < 127) ? c : '?';
  return out + (word.size() > 40 ? "...'" : "'");
}

Header parse_header(std::string_view bytes, const std::string& name) {
  Header header;
  bool have_format = false;
  size_t pos = 0;
  for (int line_number = 1;; ++line_number) {
    const size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos)
      fail(name, line_number == 1 ? "not a PLY file (empty or no header)"
                                  : "the PLY header does not end (no 'end_header' line)");
    const std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    const std::vector<std::string_view> w = split_words(line);
    const std::string where = "header line " + std::to_string(line_number) + ": ";
    if (line_number == 1) {
      if (w.size() != 1 || w[0] != "ply") fail(name, "not a PLY file (it must begin with 'ply')");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (!have_format) fail(name, "the PLY header has no 'format' line");
      header.data_begin = pos;
      return header;
    }
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") fail(name, where + "expected 'format <kind> 1.0'");
      if (w[1] == "ascii")
        header.format = Format::kAscii;
      else if (w[1] == "binary_little_endian")
        header.format = Format::kBinaryLittle;
      else if (w[1] == "binary_big_endian")
        header.format = Format::kBinaryBig;
      else
        fail(name, where + "unknown format " + shown(w[1]));
      have_format = true;
    } else if (w[0] == "element") {
      uint64_t count = 0;
      const auto parsed = w.size() == 3
                              ? std::from_chars(w[2].data(), w[2].data() + w[2].size(), count)
                              : std::from_chars_result{nullptr, std::errc::invalid_argument};
      if (parsed.ec != std::errc() || parsed.ptr != w[2].data() + w[2].size())
        fail(name, where + "expected 'element <name> <count>' with a count of 0 or more");
      for (const Element& e : header.elements)
        if (e.name == w[1]) fail(name, where + "element " + shown(w[1]) + " appears twice");
      header.elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (header.elements.empty()) fail(name, where + "a property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        const auto count_type = parse_type(w[2]);
        const auto item_type = parse_type(w[3]);
        if (!count_type || !item_type || !is_integer(*count_type))
          fail(name, where + "expected 'property list <integer type> <type> <name>'");
        p = {std::string(w[4]), *item_type, true, *count_type};
      } else if (w.size() == 3) {
        const auto type = parse_type(w[1]);
        if (!type) fail(name, where + "unknown property type " + shown(w[1]));
        p = {std::string(w[2]), *type, false, Type::kUint8};
      } else {
        fail(name, where + "expected 'property <type> <name>'");
      }
      auto& properties = header.elements.back().properties;
      for (const Property& q : properties)
        if (q.name == p.name)
          fail(name, where + "property " + shown(p.name) + " appears twice in element " +
                         shown(header.elements.back().name));
      properties.push_back(std::move(p));
    } else {
      fail(name, where + "unknown keyword " + shown(w[0]));
    }
  }
}

// The fewest bytes one item of `e` can take: a lower bound that lets lying counts be caught
// before anything is allocated from them. An ASCII value is at least one character.
uint64_t min_item_bytes(const Element& e, Format format) {
  uint64_t bytes = 0;
  for (const Property& p : e.properties)
    bytes += format == Format::kAscii ? 1 : uint64_t(size_of(p.list ? p.count_type : p.type));
  return bytes;
}

// Values of the data section in order, converted to double (exact for every PLY type).
class DataReader {
 public:
  DataReader(std::string_view data, Format format, const std::string& name)
      : data_(data), format_(format), name_(name) {}

  // Where the reader is, for messages: the element and item being read.
  void at(const Element& element, uint64_t item) {
    element_ = &element;
    item_ = item;
  }

  double value(Type type) {
    if (format_ == Format::kAscii) return ascii_value(type);
    const size_t size = size_t(size_of(type));
    if (data_.size() - pos_ < size) truncated();
    std::array<unsigned char, 8> raw{};
    std::memcpy(raw.data(), data_.data() + pos_, size);
    pos_ += size;
    const bool file_little = format_ == Format::kBinaryLittle;
    if (file_little != (std::endian::native == std::endian::little))
      std::reverse(raw.begin(), raw.begin() + long(size));
    return decode(raw.data(), type);
  }

  // A list's length, checked against the bytes left so that a lying length fails at once.
  uint64_t list_length(const Property& p) {
    const double n = value(p.count_type);
    if (n < 0) fail(name_, "in " + location() + ", a list has a negative length");
    const uint64_t count = uint64_t(n);
    const uint64_t item_bytes = format_ == Format::kAscii ? 1 : uint64_t(size_of(p.type));
    if (count > remaining() / item_bytes) truncated();
    return count;
  }

  void skip_list(const Property& p) {
    const uint64_t count = list_length(p);
    if (format_ != Format::kAscii) {
      pos_ += count * uint64_t(size_of(p.type));
      return;
    }
    for (uint64_t i = 0; i < count; ++i) value(p.type);
  }

  void skip(const Property& p) {
    if (p.list)
      skip_list(p);
    else
      value(p.type);
  }

  size_t remaining() const { return data_.size() - pos_; }

  std::string location() const {
    return element_ ? shown(element_->name) + " " + std::to_string(item_ + 1) + " of " +
                          std::to_string(element_->count)
                    : "the data";
  }

  [[noreturn]] void truncated() const {
    fail(name_, "truncated: the data ends before " + location() +
                    " is complete (the header's counts promise more than the file holds)");
  }

 private:
  static double decode(const unsigned char* raw, Type type) {
    switch (type) {
      case Type::kInt8:
        return double(int8_t(raw[0]));
      case Type::kUint8:
        return double(raw[0]);
      case Type::kInt16:
        return double(load<int16_t>(raw));
      case Type::kUint16:
        return double(load<uint16_t>(raw));
      case Type::kInt32:
        return double(load<int32_t>(raw));
      case Type::kUint32:
        return double(load<uint32_t>(raw));
      case Type::kFloat32:
        return double(load<float>(raw));
      case Type::kFloat64:
        return load<double>(raw);
    }
    return 0.0;
  }
  template <class T>
  static T load(const unsigned char* raw) {
    T v;
    std::memcpy(&v, raw, sizeof(T));
    return v;
  }

  double ascii_value(Type type) {
    while (pos_ < data_.size() && is_space(data_[pos_])) ++pos_;
    if (pos_ == data_.size()) truncated();
    size_t end = pos_;
    while (end < data_.size() && !is_space(data_[end])) ++end;
    const char* first = data_.data() + pos_;
    const char* last = data_.data() + end;
    if (first != last && *first == '+') ++first;  // from_chars refuses '+', C's strtod takes it
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc::result_out_of_range) {
      v = std::numeric_limits<double>::infinity();  // reported as not finite by the caller
    } else if (ec != std::errc() || ptr != last) {
      fail(name_, "in " + location() + ", " +
                      shown(std::string_view(data_.data() + pos_, end - pos_)) +
                      " is not a number");
    }
    pos_ = end;
    if (is_integer(type)) {
      const auto [lo, hi] = integer_range(type);
      if (!(v >= lo && v <= hi) || v != std::floor(v))
        fail(name_, "in " + location() + ", " + format(v) +
                        " is not a value of the property's integer type");
    }
    return v;
  }

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  static std::string format(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
  }

  std::string_view data_;
  size_t pos_ = 0;
  Format format_;
  const std::string& name_;
  const Element* element_ = nullptr;
  uint64_t item_ = 0;
};

// A double beyond float's range becomes +-inf explicitly (the conversion itself would be
// undefined behaviour, [conv.double]); check_finite then reports it.
float to_float(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  return float(v);
}

// Where each vertex attribute lives among the vertex element's properties (-1: absent).
struct VertexLayout {
  int position[3] = {-1, -1, -1};
  int normal[3] = {-1, -1, -1};
  int uv[2] = {-1, -1};
};

int find_scalar(const Element& e, std::string_view property, const std::string& name) {
  for (size_t i = 0; i < e.properties.size(); ++i)
    if (e.properties[i].name == property) {
      if (e.properties[i].list)
        fail(name, "vertex property " + shown(property) + " must not be a list");
      return int(i);
    }
  return -1;
}

VertexLayout vertex_layout(const Element& vertex, const std::string& name) {
  VertexLayout layout;
  const char* axes[3] = {"x", "y", "z"};
  const char* normals[3] = {"nx", "ny", "nz"};
  for (int k = 0; k < 3; ++k) {
    layout.position[k] = find_scalar(vertex, axes[k], name);
    if (layout.position[k] < 0)
      fail(name, std::string("the vertex element has no property '") + axes[k] + "'");
    layout.normal[k] = find_scalar(vertex, normals[k], name);
  }
  const int normal_parts =
      int(layout.normal[0] >= 0) + int(layout.normal[1] >= 0) + int(layout.normal[2] >= 0);
  if (normal_parts != 0 && normal_parts != 3)
    fail(name, "vertex normals need all of nx, ny and nz");
  // The uv names exporters write; the first pair present is used.
  constexpr std::array<std::array<const char*, 2>, 4> kUvNames = {
      {{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}};
  for (const auto& pair : kUvNames) {
    const int u = find_scalar(vertex, pair[0], name), v = find_scalar(vertex, pair[1], name);
    if (u < 0 && v < 0) continue;
    if (u < 0 || v < 0)
      fail(name, std::string("uvs need both '") + pair[0] + "' and '" + pair[1] + "'");
    layout.uv[0] = u;
    layout.uv[1] = v;
    break;
  }
  return layout;
}

void read_vertices(DataReader& in, const Element& vertex, const VertexLayout& layout,
                   MeshDesc& mesh) {
  const bool normals = layout.normal[0] >= 0, uvs = layout.uv[0] >= 0;
  // The count was checked against the limits and the bytes left before this allocation.
  mesh.positions.resize(vertex.count);
  if (normals) mesh.normals.resize(vertex.count);
  if (uvs) mesh.uvs.resize(vertex.count);
  std::vector<double> values(vertex.properties.size());
  for (uint64_t i = 0; i < vertex.count; ++i) {
    in.at(vertex, i);
    for (size_t k = 0; k < vertex.properties.size(); ++k) {
      const Property& p = vertex.properties[k];
      if (p.list)
        in.skip_list(p);
      else
        values[k] = in.value(p.type);
    }
    for (int k = 0; k < 3; ++k) mesh.positions[i][k] = to_float(values[size_t(layout.position[k])]);
    if (normals)
      for (int k = 0; k < 3; ++k) mesh.normals[i][k] = to_float(values[size_t(layout.normal[k])]);
    if (uvs)
      for (int k = 0; k < 2; ++k) mesh.uvs[i][k] = to_float(values[size_t(layout.uv[k])]);
  }
}

int face_index_property(const Element& face, const std::string& name) {
  for (size_t i = 0; i < face.properties.size(); ++i) {
    const Property& p = face.properties[i];
    if (p.name != "vertex_indices" && p.name != "vertex_index") continue;
    if (!p.list || !is_integer(p.type))
      fail(name, "face property " + shown(p.name) + " must be a list of integers");
    return int(i);
  }
  fail(name, "the face element has no 'vertex_indices' list");
}

void read_faces(DataReader& in, const Element& face, int index_property, const std::string& name,
                mesh_file_detail::FaceSink& sink) {
  std::vector<int64_t> corners;
  for (uint64_t f = 0; f < face.count; ++f) {
    in.at(face, f);
    for (size_t k = 0; k < face.properties.size(); ++k) {
      const Property& p = face.properties[k];
      if (int(k) != index_property) {
        in.skip(p);
        continue;
      }
      // The count is bounded by the bytes left and by the triangle cap before this resize.
      const uint64_t count = in.list_length(p);
      sink.check(count, int64_t(f));
      corners.resize(count);
      for (int64_t& c : corners) c = int64_t(in.value(p.type));
      sink.add(corners.data(), corners.size(), int64_t(f));
    }
  }
}

}  // namespace

MeshFile parse_ply(std::string_view bytes, const std::string& name, const MeshFileLimits& limits) {
  if (int64_t(bytes.size()) > limits.max_file_bytes)
    fail(name, "the file has " + std::to_string(bytes.size()) + " bytes; at most " +
                   std::to_string(limits.max_file_bytes));
  const Header header = parse_header(bytes, name);
  const std::string_view data = bytes.substr(header.data_begin);

  const Element* vertex = nullptr;
  const Element* face = nullptr;
  uint64_t needed = 0;  // a lower bound on the data bytes the header's counts need
  for (const Element& e : header.elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name == "face") face = &e;
    const uint64_t item = min_item_bytes(e, header.format);
    if (item > 0 && e.count > (data.size() - std::min<uint64_t>(needed, data.size())) / item)
      fail(name, "the header announces " + std::to_string(e.count) + " " + shown(e.name) +
                     " elements, more than the " + std::to_string(data.size()) +
                     " bytes of data can hold (a truncated file or a lying count)");
    needed += e.count * item;
  }
  if (!vertex) fail(name, "the file has no vertex element");
  if (!face) fail(name, "the file has no face element (a point cloud is not a mesh)");
  const int64_t max_vertices =
      std::min<int64_t>(limits.max_vertices, std::numeric_limits<uint32_t>::max());
  if (vertex->count > uint64_t(max_vertices))
    fail(name, "the header announces " + std::to_string(vertex->count) + " vertices; at most " +
                   std::to_string(max_vertices) + " are allowed");
  // Every face gives at least one triangle.
  if (face->count > uint64_t(limits.max_triangles))
    fail(name, "the header announces " + std::to_string(face->count) + " faces; at most " +
                   std::to_string(limits.max_triangles) + " triangles are allowed");
  const VertexLayout layout = vertex_layout(*vertex, name);
  const int index_property = face_index_property(*face, name);

  MeshFile out;
  out.faces = int64_t(face->count);
  out.mesh.indices.reserve(3 * face->count);
  mesh_file_detail::FaceSink sink(name, limits, vertex->count, out.mesh.indices);
  DataReader in(data, header.format, name);
  for (const Element& e : header.elements) {
    if (&e == vertex) {
      read_vertices(in, e, layout, out.mesh);
    } else if (&e == face) {
      read_faces(in, e, index_property, name, sink);
    } else if (!e.properties.empty()) {  // without properties an item has nothing to skip
      for (uint64_t i = 0; i < e.count; ++i) {
        in.at(e, i);
        for (const Property& p : e.properties) in.skip(p);
      }
    }
  }
  if (out.mesh.indices.empty()) fail(name, "the file has no faces");
  mesh_file_detail::check_finite(name, out.mesh);
  return out;
}

}  // namespace penumbra
