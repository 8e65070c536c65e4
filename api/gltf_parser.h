#pragma once
// The "gltf" object: a glTF 2.0 asset (.gltf or .glb in the scene's asset folder, read by
// renderer/io/gltf_file.h) placed in the scene: each node's mesh in world space (the node
// hierarchy's transforms, then the object's "transform"), its metallic-roughness materials,
// textures and emission, and its KHR_lights_punctual lights. Every file the asset names is
// resolved inside the asset folder (api/asset_path.h); every problem is reported on the
// object's "file" field, naming the file.
#include <optional>
#include <string>
#include <vector>

#include "api/asset_path.h"
#include "api/json_reader.h"
#include "api/mesh_parser.h"
#include "api/scene_loader.h"
#include "api/texture_parser.h"
#include "api/transform.h"
#include "renderer/io/gltf_file.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

// A primitive of a glTF mesh that several nodes use, placed once (objects[object], at the first
// of those nodes) and copied to the others by `transforms` (from where that object stands to
// where each other node puts it, in the same camera-rebased space): Embree instances, not copies
// of the vertices (renderer/scene/instance_input.h).
struct GltfCopies {
  std::size_t object = 0;
  std::vector<AffineTransform> transforms;
};

// What one node placed: each primitive of its mesh as objects[object] moved by `from_object`
// (identity where the node placed the primitive itself; where it copies another node's
// placement, the transform from there to here). What an "instances" object naming a glTF node
// or mesh copies (api/instances_parser.h). Primitives left out (hidden, all degenerate) are absent.
struct GltfPlacement {
  int node = 0, mesh = 0;
  std::string node_name, mesh_name;
  struct Part {
    std::size_t object = 0;
    AffineTransform from_object;
  };
  std::vector<Part> parts;
};

struct ParsedGltf {
  std::vector<ObjectDesc> objects;        // `material` indexes `materials` below
  std::vector<GltfCopies> copies;         // of some of `objects`
  std::vector<GltfPlacement> placements;  // one per node that places a mesh, in hierarchy order
  std::vector<MaterialParams> materials;  // one per glTF material, then the default material
  std::vector<LightDesc> lights;          // world space, relative to the scene's origin
  int64_t triangles = 0, vertices = 0;
  bool any_emission = false;
  AssetUse use;
};

// Reads the object at `reader` (type "gltf"): "file" and the "transform" already parsed into
// `transform` (which includes the shift to the scene's origin). nullopt with errors reported.
// A mesh that several nodes use becomes one object and instances of it (`copies`) unless
// `copies_allowed` is false (a moving object: its copies must move by its velocity, not by the
// velocity mapped through each copy's transform) or the primitive emits (an area light samples
// its own triangles).
std::optional<ParsedGltf> parse_gltf_object(ObjectReader& reader, const AffineTransform& transform,
                                            const MeshBudget& budget, const Limits& limits,
                                            const AssetFolder& assets, TextureSet& textures,
                                            bool copies_allowed = true);

// Reads a glTF asset from the asset folder with the confinement and limits of a scene: for
// `penumbra render/info model.glb`, which need its cameras, lights and bounds before building
// a scene around it. Errors are reported on `pointer`.
std::optional<GltfAsset> read_gltf_asset(const std::string& file, const std::string& pointer,
                                         const Limits& limits, const AssetFolder& assets,
                                         Diagnostics& diag);

}  // namespace penumbra::api
