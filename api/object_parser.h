#pragma once
// "objects": spheres, quads and triangle meshes with material, emission, motion and transform,
// converted to world-space renderer shapes.
#include <cstdint>
#include <string>
#include <vector>

#include "api/asset_path.h"
#include "api/json_reader.h"
#include "api/material_parser.h"
#include "api/scene_loader.h"
#include "renderer/scene/scene_input.h"


namespace penumbra::api {

// World-space coordinates (after transforms and motion) must stay within this magnitude: the
// renderer squares distances in single precision (max ~3.4e38), and (2e18)^2 still fits.
inline constexpr double kMaxCoordinate = 1e18;

struct ParsedObjects {
  std::vector<ObjectDesc> objects;
  int64_t triangles = 0;             // mesh triangles kept, after dropping degenerate ones
  int64_t vertices = 0;              // mesh vertices
  std::vector<AssetUse> assets;      // mesh files read
  std::vector<bool> material_used;   // per material handle
  bool any_emission = false;
  // What "gltf" objects bring: their materials (objects index them after the scene's own, in
  // this order) and their KHR_lights_punctual lights.
  std::vector<MaterialParams> extra_materials;
  std::vector<LightDesc> lights;
  std::vector<InstancesDesc> instances;  // "instances" objects (api/instances_parser.h)
  int64_t instance_count = 0;            // copies they place
};

// `shutter_extent` = max(|open|, |close|): motion must not carry objects out of range by then.
// `origin` (the camera position) is subtracted from every position, in double precision.
// An emission texture's file goes through `textures` (api/texture_parser.h).
ParsedObjects parse_objects(const Json* objects, const std::string& pointer,
                            const ParsedMaterials& materials, double shutter_extent,
                            const glm::dvec3& origin, const Limits& limits,
                            const AssetFolder& assets, TextureSet& textures, Diagnostics& diag);

}  // namespace penumbra::api
