#include "api/animation_parser.h"

namespace penumbra::api {

std::optional<Animation> parse_animation(const Json& value, const Limits& limits,
                                         bool camera_has_shutter, Diagnostics& diag) {
  ObjectReader r(value, "/animation", diag);
  if (!r.valid()) return std::nullopt;
  Animation a;
  bool ok = true;
  if (const Json* frames = r.get("frames", Presence::kRequired)) {
    const std::string pointer = r.pointer_of("frames");
    if (!frames->is_array() || frames->size() != 2) {
      r.error("frames", "must be an array of 2 integers [start, end] (both rendered)");
      ok = false;
    } else {
      const Range range = Range::closed(-double(limits.max_frame_number), double(limits.max_frame_number));
      const auto start = read_integer((*frames)[0], pointer + "/0", diag, range);
      const auto end = read_integer((*frames)[1], pointer + "/1", diag, range);
      if (start && end && *start > *end) {
        r.error("frames", "must be [start, end] with start <= end");
        ok = false;
      } else if (start && end && *end - *start + 1 > limits.max_frames) {
        r.error("frames", std::to_string(*end - *start + 1) + " frames exceed the limit of " +
                              std::to_string(limits.max_frames) + " (max_frames)");
        ok = false;
      } else if (start && end) {
        a.first_frame = *start;
        a.last_frame = *end;
      } else {
        ok = false;
      }
    }
  } else {
    ok = false;
  }
  // 1000 fps is beyond any film or video rate; a bound keeps i / fps meaningful in float time.
  if (auto fps = r.number("fps", Range{0.0, 1000.0, true, false})) a.fps = *fps;
  else if (r.has("fps")) ok = false;
  if (auto shutter = r.number("shutter", Range::closed(0.0, 1.0))) a.shutter = *shutter;
  else if (r.has("shutter")) ok = false;
  r.report_unknown_keys();
  if (camera_has_shutter) {
    diag.error("/camera/shutter", "a scene with an \"animation\" takes each frame's shutter from it "
                                  "([i / fps, (i + shutter) / fps]): remove /camera/shutter, or the "
                                  "animation to render one shutter interval");
    ok = false;
  }
  return ok ? std::optional<Animation>(a) : std::nullopt;
}

bool select_frame(SceneRequest& request, int64_t frame, Diagnostics& diag, const std::string& flag) {
  auto report = [&](std::string pointer, std::string message) {
    diag.error(Diagnostic{std::move(pointer), std::move(message), flag});
    return false;
  };
  if (!request.animation)
    return report("", "the scene has no \"animation\": there are no frames to choose from");
  const Animation& a = *request.animation;
  if (!a.has_frame(frame))
    return report("/animation/frames", "frame " + std::to_string(frame) + " is outside the animation's frames [" +
                                           std::to_string(a.first_frame) + ", " + std::to_string(a.last_frame) + "]");
  const FrameShutter s = frame_shutter(a, frame);
  request.scene.camera.shutter_open = float(s.open);
  request.scene.camera.shutter_close = float(s.close);
  return true;
}

}  // namespace penumbra::api
