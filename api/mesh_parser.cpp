#include "api/mesh_parser.h"

#include <cmath>
#include <limits>
#include <vector>

#include "api/object_parser.h"

namespace penumbra::api {

namespace {

// Reads a flat array of numbers in groups of three. Element errors are reported one by one on
// their own pointer (Diagnostics caps the count); the pointer string is only built on error so
// million-element arrays stay cheap.
std::optional<std::vector<glm::dvec3>> read_triples(const Json& array, const std::string& pointer,
                                                    Diagnostics& diag) {
  if (array.size() % 3 != 0) {
    diag.error(pointer, "must hold a multiple of 3 numbers (got " + std::to_string(array.size()) + ")");
    return std::nullopt;
  }
  std::vector<glm::dvec3> result(array.size() / 3);
  bool ok = true;
  for (std::size_t i = 0; i < array.size(); ++i) {
    const Json& element = array[i];
    double x = 0;
    if (element.is_number() && std::abs(x = element.get<double>()) <= kMaxMagnitude) {
      result[i / 3][int(i % 3)] = x;
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

}  // namespace

std::optional<MeshDesc> parse_mesh(ObjectReader& reader, const AffineTransform& transform,
                                    int64_t triangle_budget, int64_t max_triangles) {
  Diagnostics& diag = reader.diagnostics();
  const Json* positions_json = reader.array("positions", Presence::kRequired);
  const Json* indices_json = reader.array("indices", Presence::kRequired);
  const Json* normals_json = reader.array("normals");
  if (!positions_json || !indices_json) return std::nullopt;

  // Size checks first, so hostile sizes are rejected before any per-element work.
  bool sizes_ok = true;
  const std::size_t vertex_count = positions_json->size() / 3;
  // No mesh needs more distinct vertices than 3 per triangle.
  const uint64_t max_vertices =
      std::min<uint64_t>(3 * uint64_t(max_triangles), std::numeric_limits<uint32_t>::max());
  if (positions_json->empty()) {
    reader.error("positions", "must contain at least one vertex");
    sizes_ok = false;
  } else if (!within_count_limit(vertex_count, int64_t(max_vertices), "vertices",
                                 "3 x max_triangles", reader.pointer_of("positions"),
                                 reader.diagnostics())) {
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
  } else if (int64_t(triangle_count) > triangle_budget) {
    reader.error("indices", "the scene's triangles exceed the limit of " +
                                std::to_string(max_triangles) + " (max_triangles)");
    sizes_ok = false;
  }
  if (normals_json && normals_json->size() != positions_json->size()) {
    reader.error("normals", "must have as many numbers as \"positions\" (" +
                                std::to_string(positions_json->size()) + "), got " +
                                std::to_string(normals_json->size()));
    sizes_ok = false;
  }
  if (!sizes_ok) return std::nullopt;

  const auto positions = read_triples(*positions_json, reader.pointer_of("positions"), diag);
  const auto indices = read_indices(*indices_json, reader.pointer_of("indices"), vertex_count, diag);
  std::optional<std::vector<glm::dvec3>> normals;
  if (normals_json) {
    normals = read_triples(*normals_json, reader.pointer_of("normals"), diag);
    if (!normals) return std::nullopt;
  }
  if (!positions || !indices) return std::nullopt;

  MeshDesc mesh;
  mesh.positions.reserve(vertex_count);
  for (const glm::dvec3& p : *positions) {
    const auto world = to_world(transform.point(p));
    if (!world) {
      reader.error(reader.has("transform") ? "transform" : "positions",
                   "world-space positions must be within +-" + format_number(kMaxCoordinate));
      return std::nullopt;
    }
    mesh.positions.push_back(*world);
  }

  // Keep the triangles with nonzero area in single precision; they are what Embree will see.
  std::size_t dropped = 0, first_dropped = 0;
  mesh.indices.reserve(indices->size());
  std::vector<glm::dvec3> vertex_face_normals(normals ? vertex_count : 0, glm::dvec3(0.0));
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const uint32_t i0 = (*indices)[3 * t], i1 = (*indices)[3 * t + 1], i2 = (*indices)[3 * t + 2];
    const glm::dvec3 area = area_vector(mesh.positions[i0], mesh.positions[i1], mesh.positions[i2]);
    const double length = glm::length(area);
    if (!(length > 0) || float(length) == 0.f) {
      if (dropped++ == 0) first_dropped = t;
      continue;
    }
    mesh.indices.insert(mesh.indices.end(), {i0, i1, i2});
    if (normals)
      for (uint32_t i : {i0, i1, i2}) vertex_face_normals[i] += area;  // area-weighted
  }
  if (mesh.indices.empty()) {
    reader.error("indices", "all " + std::to_string(triangle_count) +
                                " triangles are degenerate (zero area); nothing would be rendered");
    return std::nullopt;
  }
  if (dropped > 0)
    diag.warning(child_pointer(reader.pointer_of("indices"), 3 * first_dropped),
                 "dropped " + std::to_string(dropped) +
                     " degenerate (zero-area) triangle(s); this is the first");

  if (normals) {
    // Zero-length normals cannot be interpolated; rather than dropping all shading normals of
    // the mesh, each bad one is replaced by the area-weighted average of its faces' normals,
    // which is what a modelling tool would have computed for it.
    std::size_t repaired = 0, first_repaired = 0;
    mesh.normals.reserve(vertex_count);
    for (std::size_t v = 0; v < vertex_count; ++v) {
      glm::dvec3 n = transform.normal((*normals)[v]);
      if (!(glm::length((*normals)[v]) > 0) || !(glm::length(n) > 0) || !std::isfinite(glm::length(n))) {
        if (repaired++ == 0) first_repaired = v;
        n = vertex_face_normals[v];
        // A vertex used by no kept triangle is never shaded; any unit vector will do.
        if (!(glm::length(n) > 0)) n = glm::dvec3(0, 0, 1);
      }
      const glm::dvec3 unit = glm::normalize(n);
      mesh.normals.emplace_back(float(unit.x), float(unit.y), float(unit.z));
    }
    if (repaired > 0)
      diag.warning(child_pointer(reader.pointer_of("normals"), 3 * first_repaired),
                   std::to_string(repaired) +
                       " zero-length normal(s) replaced by the average of the adjacent face "
                       "normals; this is the first");
  }
  return mesh;
}

}  // namespace penumbra::api
