#pragma once
// A syntactically valid JSON document -> SceneRequest, checking every field of format v1.
#include <optional>

#include "api/asset_path.h"
#include "api/diagnostics.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"

namespace penumbra::api {

// Returns the request only when no error was reported (warnings are fine).
// Asset paths in the scene are resolved inside `assets` (api/asset_path.h).
std::optional<SceneRequest> parse_scene(const Json& document, const Limits& limits,
                                        const AssetFolder& assets, Diagnostics& diag);

}  // namespace penumbra::api
