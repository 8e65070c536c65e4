#pragma once
// The "mesh" object -> a world-space MeshDesc: inline arrays (positions / indices / optional
// normals and uvs) or a mesh file ("file": PLY or OBJ in the scene's asset folder, read by
// renderer/io/). Both go through the same placement: transform, range checks, degenerate
// (zero-area) triangles dropped with a warning rather than rejected, so meshes exported by
// modelling tools load; zero-length normals repaired per vertex (see .cpp).
#include <cstdint>
#include <optional>
#include <string>

#include "api/asset_path.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"
#include "api/transform.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

// What the scene may still add: Limits::max_triangles and max_vertices minus what earlier meshes
// took.
struct MeshBudget {
  int64_t triangles = 0;
  int64_t vertices = 0;
};

struct ParsedMesh {
  MeshDesc mesh;
  std::optional<AssetUse> file;  // set for a mesh read from a file
};

// A mesh read from a file other than a mesh file (a glTF primitive), in its own coordinates,
// placed by `transform` exactly as a mesh file is: problems reported on the object's "file",
// naming `label`. With `allow_empty`, a mesh whose triangles are all degenerate is left out with a
// warning (nullopt, no error) instead of being an error.
std::optional<MeshDesc> place_file_mesh(ObjectReader& reader, const std::string& label,
                                        const AffineTransform& transform,
                                        const std::vector<vec3>& positions,
                                        std::vector<uint32_t> indices,
                                        const std::vector<vec3>& normals, std::vector<vec2> uvs,
                                        bool allow_empty);

std::optional<ParsedMesh> parse_mesh(ObjectReader& reader, const AffineTransform& transform,
                                     const MeshBudget& budget, const Limits& limits,
                                     const AssetFolder& assets);

}  // namespace penumbra::api
