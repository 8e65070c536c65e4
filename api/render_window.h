#pragma once
// "render": {"window": [x0, y0, x1, y1]}: render only those pixels of the image (a part of a
// frame split across machines; docs/animation-and-windows.md). `penumbra render --window
// x0,y0,x1,y1` writes the same field.
#include <string>

#include "api/diagnostics.h"
#include "api/json_reader.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

// Checks `value` (at `pointer`) against settings.width and settings.height, which must be read
// already, and sets settings.window. Every error names the pointer, or the item's (/render/window/2).
void parse_render_window(const Json& value, const std::string& pointer, RenderSettings& settings,
                         Diagnostics& diag);

}  // namespace penumbra::api
