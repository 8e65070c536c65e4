#include "api/object_parser.h"

#include <map>

#include <cmath>

#include "api/gltf_parser.h"
#include "api/instances_parser.h"
#include "api/mesh_parser.h"
#include "api/texture_parser.h"
#include "api/transform.h"

namespace penumbra::api {

namespace {

vec3 to_float(const glm::dvec3& v) { return vec3(float(v.x), float(v.y), float(v.z)); }

bool within_coordinates(const glm::dvec3& v) {
  for (int i = 0; i < 3; ++i)
    if (!(std::abs(v[i]) <= kMaxCoordinate)) return false;
  return true;
}

std::string coordinate_message() {
  return "world-space coordinates must be within +-" + format_number(kMaxCoordinate);
}

// Reports on "transform" when the transform is what pushed values out of range.
std::string_view blame(const ObjectReader& reader, std::string_view field) {
  return reader.has("transform") ? std::string_view("transform") : field;
}

std::optional<SphereDesc> parse_sphere(ObjectReader& reader, const AffineTransform& transform) {
  const auto center = reader.vec3("center", Range::any(), Presence::kRequired);
  const auto radius = reader.number("radius", Range::greater_than(0), Presence::kRequired);
  if (!center || !radius) return std::nullopt;
  const auto scale = transform.similarity_scale();
  if (!scale) {
    reader.error("transform",
                 "a sphere's transform must be a similarity (uniform scale, rotation, "
                 "translation): non-uniform scale or shear would make an ellipsoid");
    return std::nullopt;
  }
  const glm::dvec3 world_center = transform.point(*center);
  const double world_radius = *radius * *scale;
  if (!within_coordinates(world_center) || !(world_radius <= kMaxCoordinate)) {
    reader.error(blame(reader, "center"), coordinate_message());
    return std::nullopt;
  }
  if (!(float(world_radius) > 0.f)) {
    reader.error(blame(reader, "radius"), "the radius is too small for single precision");
    return std::nullopt;
  }
  return SphereDesc{to_float(world_center), float(world_radius)};
}

std::optional<QuadDesc> parse_quad(ObjectReader& reader, const AffineTransform& transform) {
  const auto origin = reader.vec3("origin", Range::any(), Presence::kRequired);
  const auto u = reader.vec3("u", Range::any(), Presence::kRequired);
  const auto v = reader.vec3("v", Range::any(), Presence::kRequired);
  if (!origin || !u || !v) return std::nullopt;
  const glm::dvec3 world_origin = transform.point(*origin);
  const glm::dvec3 world_u = transform.vector(*u), world_v = transform.vector(*v);
  if (!within_coordinates(world_origin) || !within_coordinates(world_origin + world_u) ||
      !within_coordinates(world_origin + world_v) ||
      !within_coordinates(world_origin + world_u + world_v)) {
    reader.error(blame(reader, "origin"), coordinate_message());
    return std::nullopt;
  }
  QuadDesc quad{to_float(world_origin), to_float(world_u), to_float(world_v)};
  // Judge the area on the single-precision vectors the renderer will use.
  const double area = glm::length(glm::cross(glm::dvec3(quad.u), glm::dvec3(quad.v)));
  if (!(area > 0) || float(area) == 0.f) {
    reader.diagnostics().error(reader.pointer(),
                               "zero-area quad: |u x v| must be > 0 (u and v nonzero and not "
                               "parallel)");
    return std::nullopt;
  }
  return quad;
}

}  // namespace

ParsedObjects parse_objects(const Json* objects, const std::string& pointer,
                            const ParsedMaterials& materials, double shutter_extent,
                            const glm::dvec3& origin, const Limits& limits,
                            const AssetFolder& assets, TextureSet& textures, Diagnostics& diag) {
  ParsedObjects parsed;
  parsed.material_used.assign(materials.names.size(), false);
  if (!objects) return parsed;
  if (!objects->is_array()) {
    diag.error(pointer, "must be an array of objects");
    return parsed;
  }
  if (!within_count_limit(objects->size(), limits.max_objects, "objects", "max_objects", pointer,
                          diag))
    return parsed;

  std::vector<PendingInstances> pending_instances;  // resolved once every object is read
  std::vector<int64_t> desc_index(objects->size(), -1);
  std::map<std::size_t, PlacedGltf> placed_gltf;  // what "instances" objects may copy
  for (std::size_t i = 0; i < objects->size(); ++i) {
    ObjectReader reader((*objects)[i], child_pointer(pointer, i), diag);
    if (!reader.valid()) continue;
    const std::size_t errors_before = diag.error_count();
    ObjectDesc object;

    const auto type = reader.string("type", Presence::kRequired);
    if (type && *type == kInstancesType) {  // api/instances_parser.h
      if (auto p = parse_instances(reader, limits, parsed.instance_count)) {
        parsed.instance_count += int64_t(p->transforms.size());
        pending_instances.push_back(std::move(*p));
      }
      continue;
    }
    // A glTF asset brings its own materials and emission.
    const bool is_gltf = type && *type == "gltf";
    if (is_gltf) {
      for (const char* key : {"material", "emission"})
        if (reader.has(key)) {
          reader.allow({key});
          reader.error(key, "a gltf object takes its materials and emission from the file");
        }
    } else if (const auto name = reader.string("material", Presence::kRequired)) {
      const auto it = materials.index.find(*name);
      if (it != materials.index.end()) {
        object.material = it->second;
        parsed.material_used[it->second] = true;
      } else {
        reader.error("material", "unknown material " + quote_user_string(*name) +
                                     (materials.names.empty()
                                          ? std::string(": /materials defines none")
                                          : did_you_mean(*name, materials.names)));
      }
    }
    if (is_gltf) {
    } else if (auto e = read_spectrum_field(reader, "emission", Range::at_least(0), TextureRole::kEmission, textures)) {
      object.emission = e->factor;
      object.emission_texture = e->texture;
    }
    const glm::dvec3 velocity = reader.vec3("velocity").value_or(glm::dvec3(0.0));
    const glm::dvec3 acceleration = reader.vec3("acceleration").value_or(glm::dvec3(0.0));
    object.velocity = to_float(velocity);
    object.acceleration = to_float(acceleration);
    // position(t) = p + v t + a t^2 / 2 must stay representable over the whole shutter.
    const double drift = glm::length(velocity) * shutter_extent +
                         0.5 * glm::length(acceleration) * shutter_extent * shutter_extent;
    if (!(drift <= kMaxCoordinate))
      reader.error(glm::length(acceleration) > 0 ? "acceleration" : "velocity",
                   "moves the object beyond +-" + format_number(kMaxCoordinate) +
                       " within the shutter interval");

    bool transform_ok = true;
    AffineTransform transform;
    if (const Json* t = reader.get("transform")) {
      const auto parsed_transform = parse_transform(*t, reader.pointer_of("transform"), diag);
      // Without a valid transform, shape checks would only repeat the problem; the shape's keys
      // are still declared so that typos next to it are reported.
      transform_ok = parsed_transform.has_value();
      if (parsed_transform) transform = *parsed_transform;
    }
    // Positions are handed to the renderer relative to the camera (see parse_camera).
    transform.translation -= origin;
    if (!type) continue;

    if (*type == "sphere") {
      reader.allow({"center", "radius"});
      if (transform_ok) {
        if (auto sphere = parse_sphere(reader, transform)) object.shape = *sphere;
      }
    } else if (*type == "quad") {
      reader.allow({"origin", "u", "v"});
      if (transform_ok) {
        if (auto quad = parse_quad(reader, transform)) object.shape = *quad;
      }
    } else if (*type == "mesh") {
      reader.allow({"positions", "indices", "normals", "uvs", "file"});
      const MeshBudget budget{limits.max_triangles - parsed.triangles,
                              limits.max_vertices - parsed.vertices};
      if (transform_ok) {
        if (auto mesh = parse_mesh(reader, transform, budget, limits, assets)) {
          parsed.triangles += int64_t(mesh->mesh.indices.size() / 3);
          parsed.vertices += int64_t(mesh->mesh.positions.size());
          if (mesh->file) parsed.assets.push_back(std::move(*mesh->file));
          object.shape = std::move(mesh->mesh);
        }
      }
    } else if (*type == "gltf") {
      reader.allow({"file"});
      if (!transform_ok) {
        reader.report_unknown_keys();
        continue;
      }
      const MeshBudget budget{limits.max_triangles - parsed.triangles,
                              limits.max_vertices - parsed.vertices};
      const bool moving = object.velocity != vec3(0.f) || object.acceleration != vec3(0.f);
      auto gltf = parse_gltf_object(reader, transform, budget, limits, assets, textures, !moving);
      reader.report_unknown_keys();
      if (!gltf || diag.error_count() != errors_before) continue;
      if (parsed.objects.size() + gltf->objects.size() > std::size_t(limits.max_objects)) {
        reader.error("file", "its primitives at every node make the scene's objects more than " +
                                 std::to_string(limits.max_objects) + " (max_objects)");
        continue;
      }
      int64_t copies = 0;
      for (const GltfCopies& c : gltf->copies) copies += int64_t(c.transforms.size());
      if (parsed.instance_count + copies > limits.max_instances) {
        reader.error("file", "its meshes shared by several nodes make " + std::to_string(copies) +
                                 " copies, beyond the scene's limit of " +
                                 std::to_string(limits.max_instances) + " (max_instances)");
        continue;
      }
      const std::size_t first_object = parsed.objects.size();
      bool copies_ok = true;
      for (const GltfCopies& c : gltf->copies) {
        auto desc = rebased_instances(uint32_t(first_object + c.object),
                                      std::get<MeshDesc>(gltf->objects[c.object].shape), c.transforms,
                                      origin, reader.pointer_of("file"), diag);
        if (!desc) {
          copies_ok = false;
          break;
        }
        parsed.instances.push_back(std::move(*desc));
      }
      if (!copies_ok) continue;
      parsed.instance_count += copies;
      const uint32_t offset = uint32_t(materials.names.size() + parsed.extra_materials.size());
      for (ObjectDesc& part : gltf->objects) {
        part.material += offset;
        part.velocity = object.velocity;
        part.acceleration = object.acceleration;
        parsed.objects.push_back(std::move(part));
      }
      parsed.extra_materials.insert(parsed.extra_materials.end(), gltf->materials.begin(),
                                    gltf->materials.end());
      parsed.lights.insert(parsed.lights.end(), gltf->lights.begin(), gltf->lights.end());
      parsed.triangles += gltf->triangles;
      parsed.vertices += gltf->vertices;
      parsed.any_emission = parsed.any_emission || gltf->any_emission;
      parsed.assets.push_back(std::move(gltf->use));
      placed_gltf[i] = PlacedGltf{first_object, std::move(gltf->placements)};
      continue;
    } else {
      reader.error("type", "unknown object type " + quote_user_string(*type) +
                               did_you_mean(*type, {"sphere", "quad", "mesh", "instances", "gltf"}) +
                               "; expected sphere, quad, mesh, instances or gltf");
      continue;  // the shape's keys cannot be judged without a type
    }
    reader.report_unknown_keys();
    if (diag.error_count() != errors_before) continue;
    if (!is_black(object.emission)) parsed.any_emission = true;
    desc_index[i] = int64_t(parsed.objects.size());
    parsed.objects.push_back(std::move(object));
  }
  resolve_instances(pending_instances, *objects, desc_index, parsed.objects, placed_gltf, origin,
                    limits, parsed.instance_count, parsed.instances, diag);
  return parsed;
}

}  // namespace penumbra::api
