#pragma once
// The "instances" object: copies of one mesh object placed by transforms,
//   {"type": "instances", "mesh": 0, "transforms": [{"translate": [2, 0, 0]}, {"matrix": [...]}]}
// Each transform applies after the mesh's own (to the mesh where it stands); the copies share the
// mesh's material. The mesh it names may come later in /objects, so an instances object is read
// in two steps: parse_instances while reading /objects, resolve_instances once all are read.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <map>

#include "api/gltf_parser.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"
#include "api/transform.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

inline constexpr std::string_view kInstancesType = "instances";

// "mesh": {"object": 2, "node": 3 or "Name"} or {"object": 2, "mesh": 0 or "Name"}: what a
// gltf object placed at one of its file's nodes, or at the first node (in hierarchy order) that
// places one of its meshes. The copies start from where that node put the mesh.
struct GltfSelector {
  bool by_node = true;          // else by mesh
  std::optional<int64_t> index;  // nodes[i] / meshes[i] of the file
  std::string name;             // else by name
};

// An instances object as written, its mesh not yet looked up.
struct PendingInstances {
  std::string pointer;                       // "/objects/5"
  int64_t mesh = 0;                          // index into /objects as written
  std::optional<GltfSelector> gltf;          // set when "mesh" names a glTF node or mesh
  std::vector<AffineTransform> transforms;   // scene space, before the camera rebasing
};

// What the gltf object at /objects/i placed: `first_object` is the index in the scene's object
// descriptions of its objects[0]; placement parts index from there.
struct PlacedGltf {
  std::size_t first_object = 0;
  std::vector<GltfPlacement> placements;
};

// Reads the fields of an instances object (its "type" already read). `used` = copies taken by
// earlier instances objects, against Limits::max_instances. Reports unknown keys.
std::optional<PendingInstances> parse_instances(ObjectReader& reader, const Limits& limits,
                                                int64_t used);

// Checks what each pending object's "mesh" names and converts it. `objects` is the /objects
// array; `desc_index[i]` is the index in `descs` of the object /objects/i became, or -1 (an
// instances object, or one with errors, already reported); `gltf[i]` what the gltf object
// /objects/i placed. `origin` is the camera position subtracted from every position
// (object_parser.h). A glTF node with several primitives makes one set of copies per primitive:
// `instance_count` (copies counted as written) grows by the extra ones, within
// limits.max_instances. Errors name /objects/i/mesh or /objects/i/transforms/k.
void resolve_instances(const std::vector<PendingInstances>& pending, const Json& objects,
                       const std::vector<int64_t>& desc_index, const std::vector<ObjectDesc>& descs,
                       const std::map<std::size_t, PlacedGltf>& gltf, const glm::dvec3& origin,
                       const Limits& limits, int64_t& instance_count,
                       std::vector<InstancesDesc>& out, Diagnostics& diag);

// Copies of descs[object] (a mesh that does not emit) by transforms already in the renderer's
// camera-rebased space (a glTF mesh shared by several nodes, api/gltf_parser.h). nullopt with an
// error on `pointer` if a copy leaves the coordinate range or single precision.
std::optional<InstancesDesc> rebased_instances(uint32_t object, const MeshDesc& mesh,
                                               const std::vector<AffineTransform>& transforms,
                                               const glm::dvec3& origin, const std::string& pointer,
                                               Diagnostics& diag);

}  // namespace penumbra::api
