#pragma once
// "environment": what rays that leave the scene see. Either a constant
//   {"radiance": RGB}
// or an equirectangular HDR image, Mitsuba 3 `envmap` conventions (renderer/lights/environment_map.h)
//   {"map": file, "scale": number, "rotate": {"axis", "degrees"} | "matrix": 16 numbers}.
// The image is read here, through the scene's asset folder, so an unreadable or oversized file
// is an error on /environment/map like any other invalid field.
#include <vector>

#include "api/asset_path.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

// Fills scene.environment or scene.environment_map; `value` may be null (black environment).
// Returns whether the environment emits anything (for the "no light source" warning). A map's
// file is added to *uses.
bool parse_environment(const Json* value, const AssetFolder& assets, SceneInput& scene,
                       std::vector<AssetUse>* uses, Diagnostics& diag);

}  // namespace penumbra::api
