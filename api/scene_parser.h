#pragma once
// A syntactically valid JSON document -> SceneRequest, checking every field of format v1.
#include <optional>

#include "api/diagnostics.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"

namespace penumbra::api {

// Returns the request only when no error was reported (warnings are fine).
std::optional<SceneRequest> parse_scene(const Json& document, const Limits& limits,
                                        Diagnostics& diag);

}  // namespace penumbra::api
