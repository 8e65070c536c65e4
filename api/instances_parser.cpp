#include "api/instances_parser.h"

#include <cmath>

#include "api/object_parser.h"

namespace penumbra::api {
namespace {

// Fields of other objects that an instances object takes from its mesh, with why.
struct Inherited {
  std::string_view key;
  const char* why;
};
constexpr Inherited kInherited[] = {
    {"material", "copies use their mesh's material"},
    {"emission", "copies of an emitting mesh are not supported (see docs/scene-format.md)"},
    {"velocity", "copies move as their mesh moves"},
    {"acceleration", "copies move as their mesh moves"},
    {"transform", "each copy's transform is in \"transforms\"; the mesh's own applies first"},
};

std::string describe(const Json& object) {
  const Json* type = object.is_object() && object.contains("type") ? &object["type"] : nullptr;
  if (!type || !type->is_string()) return "an object without a valid type";
  const std::string name = type->get<std::string>();
  if (name == "sphere") return "a sphere";
  if (name == "quad") return "a quad";
  if (name == "mesh") return "a mesh";
  if (name == "gltf") return "a gltf object";
  if (name == kInstancesType) return "an instances object";
  return "an object of unknown type";
}

bool is_type(const Json& object, std::string_view type) {
  return object.is_object() && object.contains("type") && object["type"].is_string() &&
         object["type"].get<std::string>() == type;
}

struct Box {
  glm::dvec3 lo{kMaxCoordinate}, hi{-kMaxCoordinate};
};

Box mesh_bounds(const MeshDesc& mesh) {
  Box b;
  for (const vec3& p : mesh.positions) {
    b.lo = glm::min(b.lo, glm::dvec3(p));
    b.hi = glm::max(b.hi, glm::dvec3(p));
  }
  return b;
}

// The camera-rebased form of x' = A x + b: positions are handed over as x - origin, so
// x' - origin = A (x - origin) + (A origin + b - origin), computed in double.
AffineTransform rebased(const AffineTransform& t, const glm::dvec3& origin) {
  return AffineTransform{t.linear, t.linear * origin + t.translation - origin};
}

InstanceTransform to_float(const AffineTransform& t) {
  InstanceTransform out;
  out.linear = glm::mat3(t.linear);
  out.translation = vec3(t.translation);
  return out;
}

// Whether the copy's corners stay within the coordinate range, and its single-precision matrix
// is usable: finite, with an inverse in single precision (Embree inverts it in float).
bool usable(const InstanceTransform& t, const Box& bounds, const glm::dvec3& origin) {
  const glm::dmat3 a(t.linear);
  const double det = glm::determinant(a);
  if (!std::isfinite(det) || float(det) == 0.f || !std::isfinite(1.f / float(det))) return false;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner((k & 1) ? bounds.hi.x : bounds.lo.x, (k & 2) ? bounds.hi.y : bounds.lo.y,
                            (k & 4) ? bounds.hi.z : bounds.lo.z);
    const glm::dvec3 world = a * corner + glm::dvec3(t.translation) + origin;
    for (int i = 0; i < 3; ++i)
      if (!(std::abs(world[i]) <= kMaxCoordinate)) return false;
  }
  return true;
}

// {"node": i or "Name"} or {"mesh": i or "Name"}, exactly one (the "object" key read by the caller).
std::optional<GltfSelector> parse_gltf_selector(ObjectReader& selector) {
  const bool node = selector.has("node"), mesh = selector.has("mesh");
  if (node == mesh) {
    selector.allow({"node", "mesh"});
    selector.diagnostics().error(node ? selector.pointer_of("mesh") : selector.pointer(),
                   node ? "give \"node\" or \"mesh\", not both"
                        : "must name a glTF node or mesh: {\"object\": i, \"node\": n or \"name\"} "
                          "or {\"object\": i, \"mesh\": m or \"name\"}");
    return std::nullopt;
  }
  GltfSelector out;
  out.by_node = node;
  const std::string_view key = node ? "node" : "mesh";
  const Json* value = selector.get(key);
  if (value->is_string()) {
    out.name = value->get<std::string>();
    if (out.name.empty() || out.name.size() > 1024) {
      selector.error(key, "a name must have 1 to 1024 characters");
      return std::nullopt;
    }
  } else if (const auto index = selector.integer(key, Range::at_least(0))) {
    out.index = *index;
  } else {
    return std::nullopt;
  }
  return out;
}

}  // namespace

std::optional<PendingInstances> parse_instances(ObjectReader& reader, const Limits& limits,
                                                int64_t used) {
  Diagnostics& diag = reader.diagnostics();
  const std::size_t errors_before = diag.error_count();
  PendingInstances pending;
  pending.pointer = reader.pointer();
  for (const Inherited& field : kInherited)
    if (reader.has(field.key)) {
      reader.allow({field.key});
      reader.error(field.key, std::string("not allowed on an instances object: ") + field.why);
    }
  const Json* mesh = reader.get("mesh", Presence::kRequired);
  if (mesh && mesh->is_object()) {
    ObjectReader selector(*mesh, reader.pointer_of("mesh"), diag);
    if (const auto object = selector.integer("object", Range::at_least(0), Presence::kRequired))
      pending.mesh = *object;
    pending.gltf = parse_gltf_selector(selector);
    selector.report_unknown_keys();
  } else if (mesh) {
    if (const auto index = reader.integer("mesh", Range::at_least(0), Presence::kRequired))
      pending.mesh = *index;
  }
  if (const Json* transforms = reader.array("transforms", Presence::kRequired)) {
    const std::string pointer = reader.pointer_of("transforms");
    const int64_t left = std::max<int64_t>(0, limits.max_instances - used);
    if (int64_t(transforms->size()) > left) {
      diag.error(pointer, std::to_string(transforms->size()) + " copies exceed the limit of " +
                              std::to_string(limits.max_instances) +
                              " per scene (max_instances)" +
                              (used > 0 ? ", " + std::to_string(used) + " taken by earlier objects"
                                        : std::string()));
    } else {
      pending.transforms.reserve(transforms->size());
      for (std::size_t k = 0; k < transforms->size(); ++k)
        if (auto t = parse_transform((*transforms)[k], child_pointer(pointer, k), diag))
          pending.transforms.push_back(*t);
    }
  }
  reader.report_unknown_keys();
  if (diag.error_count() != errors_before) return std::nullopt;
  return pending;
}

namespace {

// A part to copy: descs[object], first moved by `from_object` (in the camera-rebased space).
struct CopySource {
  std::size_t object = 0;
  AffineTransform from_object;
};

std::string selector_text(const GltfSelector& g) {
  const char* what = g.by_node ? "node" : "mesh";
  return g.index ? std::string(what) + "s[" + std::to_string(*g.index) + "]"
                 : std::string(what) + " " + quote_user_string(g.name);
}

// The parts of what `g` names in a gltf object, or nullopt with an error on `field`.
std::optional<std::vector<CopySource>> gltf_sources(const GltfSelector& g, const PlacedGltf& placed,
                                                    const std::string& field,
                                                    const std::string& target_pointer,
                                                    Diagnostics& diag) {
  const GltfPlacement* found = nullptr;
  for (const GltfPlacement& pl : placed.placements) {
    const int id = g.by_node ? pl.node : pl.mesh;
    const std::string& name = g.by_node ? pl.node_name : pl.mesh_name;
    if (g.index ? id != *g.index : name != g.name) continue;
    if (!found) {
      found = &pl;
    } else if (!g.index && (g.by_node ? found->node != pl.node : found->mesh != pl.mesh)) {
      diag.error(field, "the file of " + target_pointer + " has several " +
                            (g.by_node ? "nodes" : "meshes") + " named " + quote_user_string(g.name) +
                            " (" + (g.by_node ? "nodes[" : "meshes[") +
                            std::to_string(g.by_node ? found->node : found->mesh) + "] and [" +
                            std::to_string(g.by_node ? pl.node : pl.mesh) + "]): name it by index");
      return std::nullopt;
    }
  }
  if (!found) {
    diag.error(field, (g.by_node ? selector_text(g) + " of the file of " + target_pointer +
                                       " places no mesh"
                                 : "no node of the file of " + target_pointer + " places " +
                                       selector_text(g)) +
                          " (only meshes placed by a node of the file's scene can be copied; "
                          "nodes with a zero scale are left out)");
    return std::nullopt;
  }
  if (found->parts.empty()) {
    diag.error(field, selector_text(g) + " of " + target_pointer +
                          " places nothing (its primitives are hidden or degenerate)");
    return std::nullopt;
  }
  std::vector<CopySource> out;
  for (const GltfPlacement::Part& part : found->parts)
    out.push_back({placed.first_object + part.object, part.from_object});
  return out;
}

}  // namespace

void resolve_instances(const std::vector<PendingInstances>& pending, const Json& objects,
                       const std::vector<int64_t>& desc_index, const std::vector<ObjectDesc>& descs,
                       const std::map<std::size_t, PlacedGltf>& gltf, const glm::dvec3& origin,
                       const Limits& limits, int64_t& instance_count,
                       std::vector<InstancesDesc>& out, Diagnostics& diag) {
  for (const PendingInstances& p : pending) {
    const std::string field = p.pointer + "/mesh" + (p.gltf ? "/object" : "");
    if (p.mesh >= int64_t(objects.size())) {
      diag.error(field, "index " + std::to_string(p.mesh) + " is out of range: /objects has " +
                            std::to_string(objects.size()) + " entries");
      continue;
    }
    const Json& target = objects[std::size_t(p.mesh)];
    const std::string target_pointer = child_pointer("/objects", std::size_t(p.mesh));
    std::vector<CopySource> sources;
    if (p.gltf) {
      if (!is_type(target, "gltf")) {
        diag.error(field, target_pointer + " is " + describe(target) +
                              ": a {\"node\"} or {\"mesh\"} selector names a gltf object");
        continue;
      }
      const auto placed = gltf.find(std::size_t(p.mesh));
      if (placed == gltf.end()) continue;  // the gltf object has errors of its own, reported
      auto found = gltf_sources(*p.gltf, placed->second, p.pointer + "/mesh", target_pointer, diag);
      if (!found) continue;
      sources = std::move(*found);
    } else {
      if (!is_type(target, "mesh")) {
        diag.error(field, target_pointer + " is " + describe(target) +
                              (is_type(target, kInstancesType)
                                   ? ": copies of copies are not supported (one level of instancing)"
                               : is_type(target, "gltf")
                                   ? ": name one of its nodes or meshes, {\"object\": " +
                                         std::to_string(p.mesh) + ", \"node\": n or \"name\"}"
                                   : ": only a mesh can be instanced"));
        continue;
      }
      const int64_t index = desc_index[std::size_t(p.mesh)];
      if (index < 0) continue;  // the mesh has errors of its own, already reported
      sources.push_back({std::size_t(index), AffineTransform{}});
    }
    const int64_t extra = int64_t(sources.size() - 1) * int64_t(p.transforms.size());
    if (extra > 0 && instance_count + extra > limits.max_instances) {
      diag.error(p.pointer + "/transforms",
                 std::to_string(p.transforms.size()) + " copies of " + std::to_string(sources.size()) +
                     " primitives exceed the limit of " + std::to_string(limits.max_instances) +
                     " per scene (max_instances)");
      continue;
    }
    bool ok = true;
    std::vector<InstancesDesc> made;
    for (const CopySource& source : sources) {
      const ObjectDesc& mesh_object = descs[source.object];
      if (!is_black(mesh_object.emission) || mesh_object.emission_texture) {
        diag.error(p.pointer + "/mesh",
                   target_pointer + (p.gltf ? " " + selector_text(*p.gltf) : std::string()) +
                       " emits light: copies of an emitting mesh are not supported; write "
                       "each emitting copy as an object of its own");
        ok = false;
        break;
      }
      const Box bounds = mesh_bounds(std::get<MeshDesc>(mesh_object.shape));
      InstancesDesc desc;
      desc.object = uint32_t(source.object);
      desc.transforms.reserve(p.transforms.size());
      for (std::size_t k = 0; k < p.transforms.size(); ++k) {
        const InstanceTransform t =
            to_float(compose(rebased(p.transforms[k], origin), source.from_object));
        if (!usable(t, bounds, origin)) {
          diag.error(child_pointer(p.pointer + "/transforms", k),
                     "places the copy beyond world-space coordinates +-" +
                         format_number(kMaxCoordinate) +
                         " or scales it beyond single precision");
          ok = false;
          continue;
        }
        desc.transforms.push_back(t);
      }
      made.push_back(std::move(desc));
    }
    if (!ok) continue;
    instance_count += extra;
    for (InstancesDesc& d : made) out.push_back(std::move(d));
  }
}

std::optional<InstancesDesc> rebased_instances(uint32_t object, const MeshDesc& mesh,
                                               const std::vector<AffineTransform>& transforms,
                                               const glm::dvec3& origin, const std::string& pointer,
                                               Diagnostics& diag) {
  const Box bounds = mesh_bounds(mesh);
  InstancesDesc desc;
  desc.object = object;
  desc.transforms.reserve(transforms.size());
  for (const AffineTransform& t : transforms) {
    const InstanceTransform copy = to_float(t);
    if (!usable(copy, bounds, origin)) {
      diag.error(pointer, "a copy of a shared mesh lands beyond world-space coordinates +-" +
                              format_number(kMaxCoordinate) + " or scales it beyond single precision");
      return std::nullopt;
    }
    desc.transforms.push_back(copy);
  }
  return desc;
}

}  // namespace penumbra::api
