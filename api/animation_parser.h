#pragma once
// Reading a scene's "animation" and choosing a frame of it (api/animation.h).
#include <optional>
#include <string>

#include "api/animation.h"
#include "api/diagnostics.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"

namespace penumbra::api {

// Reads the "animation" member at /animation. `camera_has_shutter`: the scene also gives
// /camera/shutter, which an animation replaces frame by frame: an error (one source of time).
std::optional<Animation> parse_animation(const Json& value, const Limits& limits,
                                         bool camera_has_shutter, Diagnostics& diag);

// Makes `request` render frame `frame` of its animation: sets the camera's shutter. An error
// (on /animation/frames, carrying `flag` when a command-line flag chose the frame) when the
// scene has no animation or the frame is outside its range.
bool select_frame(SceneRequest& request, int64_t frame, Diagnostics& diag, const std::string& flag = {});

}  // namespace penumbra::api
