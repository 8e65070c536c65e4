#pragma once
// The `penumbra render` flags that override a scene's "render" block (--width 640 ...).
// Each is written into the parsed document's /render object before the one typed parse, so it
// meets the very ranges, cross-field checks and limits of the JSON field it replaces (a --width
// within its own bounds must not slip past max_pixels), with the same message, naming the flag:
// "--width (/render/width): must be <= 8192 (max_width)". --threads, which the scene format does
// not have, is checked by read_thread_count.
#include <optional>
#include <span>
#include <string_view>

#include "api/diagnostics.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"

namespace penumbra::api {

inline constexpr std::string_view kThreadsFlag = "--threads";
// --threads N: 0 = all hardware threads. 4096 is beyond any machine this runs on, yet stops a
// typo from asking for millions of threads; `penumbra serve --render-threads` has the same bound.
inline constexpr int kMaxThreads = 4096;

// Every override flag: one per member of the "render" block ("--max-depth" for max_depth; its
// alias --aov for --outputs, "--aov albedo,normal" is the list ["albedo", "normal"]), then
// --threads.
std::span<const std::string_view> render_override_flags();
// A flag that may stand alone, meaning true ("--denoise"), or take true/false.
bool is_switch_override_flag(std::string_view flag);
bool is_render_override_flag(std::string_view flag);

// The JSON value a flag's text stands for: the scalar it spells as JSON (64, 2.5, -1, true),
// else the text as a string, so "--width abc" reads "must be an integer (got a string)" exactly
// as "width": "abc" would. --integrator, whose field is a string, always takes the text.
Json override_value(const RenderOverride& override_flag);

// --threads: an integer in [0, kMaxThreads]; an error carries the flag and pointer "".
std::optional<int> read_thread_count(const Json& value, Diagnostics& diag);

// Writes the overrides into document["render"] (created when absent; a later flag wins over an
// earlier one, as on any command line) and returns --threads when given. A document or "render"
// that is not an object is left alone: parse_scene reports it.
std::optional<int> apply_render_overrides(Json& document, std::span<const RenderOverride> overrides,
                                          Diagnostics& diag);

}  // namespace penumbra::api
