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
InstanceTransform rebased(const AffineTransform& t, const glm::dvec3& origin) {
  InstanceTransform out;
  out.linear = glm::mat3(t.linear);
  const glm::dvec3 translation = t.linear * origin + t.translation - origin;
  out.translation = vec3(translation);
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
  if (const auto mesh = reader.integer("mesh", Range::at_least(0), Presence::kRequired))
    pending.mesh = *mesh;
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

void resolve_instances(const std::vector<PendingInstances>& pending, const Json& objects,
                       const std::vector<int64_t>& desc_index, const std::vector<ObjectDesc>& descs,
                       const glm::dvec3& origin, std::vector<InstancesDesc>& out, Diagnostics& diag) {
  for (const PendingInstances& p : pending) {
    const std::string field = p.pointer + "/mesh";
    if (p.mesh >= int64_t(objects.size())) {
      diag.error(field, "index " + std::to_string(p.mesh) + " is out of range: /objects has " +
                            std::to_string(objects.size()) + " entries");
      continue;
    }
    const Json& target = objects[std::size_t(p.mesh)];
    const std::string target_pointer = child_pointer("/objects", std::size_t(p.mesh));
    if (!is_type(target, "mesh")) {
      diag.error(field, target_pointer + " is " + describe(target) +
                            (is_type(target, kInstancesType)
                                 ? ": copies of copies are not supported (one level of instancing)"
                                 : ": only a mesh can be instanced"));
      continue;
    }
    const int64_t index = desc_index[std::size_t(p.mesh)];
    if (index < 0) continue;  // the mesh has errors of its own, already reported
    const ObjectDesc& mesh_object = descs[std::size_t(index)];
    if (!is_black(mesh_object.emission)) {
      diag.error(field, target_pointer +
                            " emits light: copies of an emitting mesh are not supported; write "
                            "each emitting copy as a mesh object of its own");
      continue;
    }
    const Box bounds = mesh_bounds(std::get<MeshDesc>(mesh_object.shape));
    InstancesDesc desc;
    desc.object = uint32_t(index);
    desc.transforms.reserve(p.transforms.size());
    bool ok = true;
    for (std::size_t k = 0; k < p.transforms.size(); ++k) {
      const InstanceTransform t = rebased(p.transforms[k], origin);
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
    if (ok) out.push_back(std::move(desc));
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
    InstanceTransform copy;
    copy.linear = glm::mat3(t.linear);
    copy.translation = vec3(t.translation);
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
