#include "api/mesh_parser.h"

#include <cmath>
#include <limits>
#include <new>
#include <vector>

#include "api/object_parser.h"
#include "renderer/io/mesh_file.h"

namespace penumbra::api {

namespace {

// Reads a flat array of numbers in groups of N. Element errors are reported one by one on their
// own pointer (Diagnostics caps the count); the pointer string is only built on error so
// million-element arrays stay cheap.
template <int N>
std::optional<std::vector<glm::vec<N, double>>> read_groups(const Json& array,
                                                            const std::string& pointer,
                                                            Diagnostics& diag) {
  if (array.size() % N != 0) {
    diag.error(pointer, "must hold a multiple of " + std::to_string(N) + " numbers (got " +
                            std::to_string(array.size()) + ")");
    return std::nullopt;
  }
  std::vector<glm::vec<N, double>> result(array.size() / N);
  bool ok = true;
  for (std::size_t i = 0; i < array.size(); ++i) {
    const Json& element = array[i];
    double x = 0;
    if (element.is_number() && std::abs(x = element.get<double>()) <= kMaxMagnitude) {
      result[i / N][int(i % N)] = x;
    } else {
      read_number(element, child_pointer(pointer, i), diag);  // reports the precise problem
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return result;
}

std::optional<std::vector<uint32_t>> read_indices(const Json& array, const std::string& pointer,
                                                  std::size_t vertex_count, Diagnostics& diag) {
  std::vector<uint32_t> result(array.size());
  bool ok = true;
  for (std::size_t i = 0; i < array.size(); ++i) {
    const Json& element = array[i];
    if (element.is_number_unsigned() && element.get<uint64_t>() < vertex_count) {
      result[i] = uint32_t(element.get<uint64_t>());
      continue;
    }
    const std::string p = child_pointer(pointer, i);
    const auto index = read_integer(element, p, diag);  // accepts an integral float like 2.0
    if (!index) {
      ok = false;
    } else if (*index < 0 || uint64_t(*index) >= vertex_count) {
      diag.error(p, "index " + std::to_string(*index) + " is out of range: the mesh has " +
                        std::to_string(vertex_count) + " vertices");
      ok = false;
    } else {
      result[i] = uint32_t(*index);
    }
  }
  if (!ok) return std::nullopt;
  return result;
}

std::optional<vec3> to_world(const glm::dvec3& p) {
  for (int i = 0; i < 3; ++i)
    if (!(std::abs(p[i]) <= kMaxCoordinate)) return std::nullopt;
  return vec3(float(p.x), float(p.y), float(p.z));
}

// Twice the area vector of a triangle, from the single-precision positions the renderer sees.
glm::dvec3 area_vector(const vec3& a, const vec3& b, const vec3& c) {
  return glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
}

// Where a mesh's problems are reported. Inline arrays: on the element's own pointer
// (/objects/4/indices/9). A file: on its "file" field, the message naming the file and the
// triangle or vertex (counting from 1, as a text editor's line numbers).
class MeshSite {
 public:
  explicit MeshSite(const ObjectReader& reader, std::string file = {})
      : reader_(reader), file_(std::move(file)) {}

  bool is_file() const { return !file_.empty(); }
  std::string pointer(std::string_view field, std::size_t element) const {
    return is_file() ? reader_.pointer_of("file")
                     : child_pointer(reader_.pointer_of(field), element);
  }
  std::string pointer(std::string_view field) const {
    return reader_.pointer_of(is_file() ? "file" : field);
  }
  // `what` names the element in a file: "triangle 17".
  std::string message(const std::string& text, const std::string& what = {}) const {
    if (!is_file()) return text;
    return quote_user_string(file_) + ": " + text + (what.empty() ? "" : "; the first is " + what);
  }

 private:
  const ObjectReader& reader_;
  std::string file_;
};

// Object-space arrays -> the world-space MeshDesc, shared by inline and file meshes. `V` is
// double (JSON) or float (files) precision; every position is transformed in double either way.
template <class V>
std::optional<MeshDesc> place_mesh(ObjectReader& reader, const MeshSite& site,
                                   const AffineTransform& transform,
                                   const std::vector<V>& positions, std::vector<uint32_t> indices,
                                   const std::vector<V>& normals, std::vector<vec2> uvs,
                                   bool allow_empty = false) {
  Diagnostics& diag = reader.diagnostics();
  const std::size_t vertex_count = positions.size();
  const std::size_t triangle_count = indices.size() / 3;
  MeshDesc mesh;
  mesh.positions.reserve(vertex_count);
  for (const V& p : positions) {
    const auto world = to_world(transform.point(glm::dvec3(p)));
    if (!world) {
      reader.error(
          reader.has("transform") ? "transform"
          : site.is_file()        ? "file"
                                  : "positions",
          site.message("world-space positions must be within +-" + format_number(kMaxCoordinate)));
      return std::nullopt;
    }
    mesh.positions.push_back(*world);
  }

  // Keep the triangles with nonzero area in single precision; they are what Embree will see.
  // Compacted in place: a kept triangle never moves forward.
  std::size_t dropped = 0, first_dropped = 0, kept = 0;
  std::vector<glm::dvec3> vertex_face_normals(normals.empty() ? 0 : vertex_count, glm::dvec3(0.0));
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
    const glm::dvec3 area = area_vector(mesh.positions[i0], mesh.positions[i1], mesh.positions[i2]);
    const double length = glm::length(area);
    if (!(length > 0) || float(length) == 0.f) {
      if (dropped++ == 0) first_dropped = t;
      continue;
    }
    indices[3 * kept] = i0;
    indices[3 * kept + 1] = i1;
    indices[3 * kept + 2] = i2;
    ++kept;
    if (!normals.empty())
      for (uint32_t i : {i0, i1, i2}) vertex_face_normals[i] += area;  // area-weighted
  }
  indices.resize(3 * kept);
  mesh.indices = std::move(indices);
  if (mesh.indices.empty() && allow_empty) {
    diag.warning(site.pointer("indices"),
                 site.message("all " + std::to_string(triangle_count) +
                              " triangles are degenerate (zero area): left out"));
    return std::nullopt;
  }
  if (mesh.indices.empty()) {
    diag.error(site.pointer("indices"),
               site.message("all " + std::to_string(triangle_count) +
                            " triangles are degenerate (zero area); nothing would be rendered"));
    return std::nullopt;
  }
  if (dropped > 0)
    diag.warning(
        site.pointer("indices", 3 * first_dropped),
        site.message("dropped " + std::to_string(dropped) + " degenerate (zero-area) triangle(s)" +
                         (site.is_file() ? "" : "; this is the first"),
                     "triangle " + std::to_string(first_dropped + 1)));

  if (!normals.empty()) {
    // Zero-length normals cannot be interpolated; rather than dropping all shading normals of
    // the mesh, each bad one is replaced by the area-weighted average of its faces' normals,
    // which is what a modelling tool would have computed for it.
    std::size_t repaired = 0, first_repaired = 0;
    mesh.normals.reserve(vertex_count);
    for (std::size_t v = 0; v < vertex_count; ++v) {
      const glm::dvec3 given(normals[v]);
      glm::dvec3 n = transform.normal(given);
      if (!(glm::length(given) > 0) || !(glm::length(n) > 0) || !std::isfinite(glm::length(n))) {
        if (repaired++ == 0) first_repaired = v;
        n = vertex_face_normals[v];
        // A vertex used by no kept triangle is never shaded; any unit vector will do.
        if (!(glm::length(n) > 0)) n = glm::dvec3(0, 0, 1);
      }
      const glm::dvec3 unit = glm::normalize(n);
      mesh.normals.emplace_back(float(unit.x), float(unit.y), float(unit.z));
    }
    if (repaired > 0)
      diag.warning(site.pointer("normals", 3 * first_repaired),
                   site.message(std::to_string(repaired) +
                                    " zero-length normal(s) replaced by the average of the "
                                    "adjacent face normals" +
                                    (site.is_file() ? "" : "; this is the first"),
                                "vertex " + std::to_string(first_repaired + 1)));
  }
  mesh.uvs = std::move(uvs);
  return mesh;
}

std::optional<MeshDesc> parse_inline_mesh(ObjectReader& reader, const AffineTransform& transform,
                                          const MeshBudget& budget, const Limits& limits) {
  Diagnostics& diag = reader.diagnostics();
  const Json* positions_json = reader.array("positions", Presence::kRequired);
  const Json* indices_json = reader.array("indices", Presence::kRequired);
  const Json* normals_json = reader.array("normals");
  const Json* uvs_json = reader.array("uvs");
  if (!positions_json || !indices_json) return std::nullopt;

  // Size checks first, so hostile sizes are rejected before any per-element work.
  bool sizes_ok = true;
  const std::size_t vertex_count = positions_json->size() / 3;
  if (positions_json->empty()) {
    reader.error("positions", "must contain at least one vertex");
    sizes_ok = false;
  } else if (int64_t(vertex_count) > budget.vertices) {
    reader.error("positions", "the scene's mesh vertices exceed the limit of " +
                                  std::to_string(limits.max_vertices) + " (max_vertices)");
    sizes_ok = false;
  }
  const std::size_t triangle_count = indices_json->size() / 3;
  if (indices_json->size() % 3 != 0) {
    reader.error("indices", "must hold a multiple of 3 indices (got " +
                                std::to_string(indices_json->size()) + ")");
    sizes_ok = false;
  } else if (triangle_count == 0) {
    reader.error("indices", "must contain at least one triangle");
    sizes_ok = false;
  } else if (int64_t(triangle_count) > budget.triangles) {
    reader.error("indices", "the scene's triangles exceed the limit of " +
                                std::to_string(limits.max_triangles) + " (max_triangles)");
    sizes_ok = false;
  }
  if (normals_json && normals_json->size() != positions_json->size()) {
    reader.error("normals", "must have as many numbers as \"positions\" (" +
                                std::to_string(positions_json->size()) + "), got " +
                                std::to_string(normals_json->size()));
    sizes_ok = false;
  }
  if (uvs_json && uvs_json->size() != 2 * vertex_count) {
    reader.error("uvs", "must hold 2 numbers per vertex (" + std::to_string(2 * vertex_count) +
                            "), got " + std::to_string(uvs_json->size()));
    sizes_ok = false;
  }
  if (!sizes_ok) return std::nullopt;

  const auto positions = read_groups<3>(*positions_json, reader.pointer_of("positions"), diag);
  const auto indices =
      read_indices(*indices_json, reader.pointer_of("indices"), vertex_count, diag);
  std::optional<std::vector<glm::dvec3>> normals;
  if (normals_json) {
    normals = read_groups<3>(*normals_json, reader.pointer_of("normals"), diag);
    if (!normals) return std::nullopt;
  }
  std::vector<vec2> uvs;
  if (uvs_json) {
    const auto pairs = read_groups<2>(*uvs_json, reader.pointer_of("uvs"), diag);
    if (!pairs) return std::nullopt;
    uvs.reserve(pairs->size());
    for (const glm::dvec2& uv : *pairs) uvs.emplace_back(float(uv.x), float(uv.y));
  }
  if (!positions || !indices) return std::nullopt;
  static const std::vector<glm::dvec3> kNoNormals;
  return place_mesh(reader, MeshSite(reader), transform, *positions, std::move(*indices),
                    normals ? *normals : kNoNormals, std::move(uvs));
}

// What a file held, before degenerate triangles are dropped (that warning counts those).
std::string describe(const MeshFile& file) {
  std::string s = std::to_string(file.mesh.indices.size() / 3) + " triangles (" +
                  std::to_string(file.faces) + " faces), " +
                  std::to_string(file.mesh.positions.size()) + " vertices";
  if (!file.mesh.normals.empty()) s += ", normals";
  if (!file.mesh.uvs.empty()) s += ", uvs";
  return s;
}

std::optional<ParsedMesh> parse_file_mesh(ObjectReader& reader, const AffineTransform& transform,
                                          const MeshBudget& budget, const Limits& limits,
                                          const AssetFolder& assets) {
  const auto file = reader.string("file", Presence::kRequired);
  for (const char* inline_field : {"positions", "indices", "normals", "uvs"})
    if (reader.has(inline_field))
      reader.error(inline_field, "a mesh takes either \"file\" or inline arrays, not both");
  if (!file) return std::nullopt;
  const std::string pointer = reader.pointer_of("file");
  Diagnostics& diag = reader.diagnostics();
  if (!is_mesh_file_name(*file)) {
    diag.error(pointer, "must name a .ply or .obj file (got " + quote_user_string(*file) + ")");
    return std::nullopt;
  }
  const auto path = resolve_asset_path(assets, *file, pointer, diag);
  if (!path) return std::nullopt;

  MeshFileLimits file_limits;
  file_limits.max_file_bytes = limits.max_mesh_file_bytes;
  file_limits.max_vertices = std::max<int64_t>(budget.vertices, 0);
  file_limits.max_triangles = std::max<int64_t>(budget.triangles, 0);
  MeshFile loaded;
  try {
    loaded = read_mesh_file(*path, quote_user_string(*file), file_limits);
  } catch (const MeshFileError& e) {
    diag.error(pointer, e.what());
    return std::nullopt;
  } catch (const std::bad_alloc&) {
    diag.error(pointer, quote_user_string(*file) + ": out of memory while reading the file");
    return std::nullopt;
  }
  for (const std::string& warning : loaded.warnings) diag.warning(pointer, warning);

  AssetUse use{pointer, *file, describe(loaded)};
  auto mesh =
      place_mesh(reader, MeshSite(reader, *file), transform, loaded.mesh.positions,
                 std::move(loaded.mesh.indices), loaded.mesh.normals, std::move(loaded.mesh.uvs));
  if (!mesh) return std::nullopt;
  return ParsedMesh{std::move(*mesh), std::move(use)};
}

}  // namespace

std::optional<MeshDesc> place_file_mesh(ObjectReader& reader, const std::string& label,
                                        const AffineTransform& transform,
                                        const std::vector<vec3>& positions,
                                        std::vector<uint32_t> indices,
                                        const std::vector<vec3>& normals, std::vector<vec2> uvs,
                                        bool allow_empty) {
  return place_mesh(reader, MeshSite(reader, label), transform, positions, std::move(indices),
                    normals, std::move(uvs), allow_empty);
}

std::optional<ParsedMesh> parse_mesh(ObjectReader& reader, const AffineTransform& transform,
                                     const MeshBudget& budget, const Limits& limits,
                                     const AssetFolder& assets) {
  if (reader.has("file")) return parse_file_mesh(reader, transform, budget, limits, assets);
  auto mesh = parse_inline_mesh(reader, transform, budget, limits);
  if (!mesh) return std::nullopt;
  return ParsedMesh{std::move(*mesh), std::nullopt};
}

}  // namespace penumbra::api
