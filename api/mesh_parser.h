#pragma once
// The "mesh" object: flat positions / indices / optional normals -> a world-space MeshDesc.
// Degenerate (zero-area) triangles are dropped with a warning rather than rejected, so meshes
// exported by modelling tools load; zero-length normals are repaired per vertex (see .cpp).
#include <cstdint>
#include <optional>

#include "api/json_reader.h"
#include "api/transform.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

// `triangle_budget` = how many triangles the scene may still add (Limits::max_triangles minus
// those of earlier meshes).
std::optional<MeshDesc> parse_mesh(ObjectReader& reader, const AffineTransform& transform,
                                    int64_t triangle_budget, int64_t max_triangles);

}  // namespace penumbra::api
