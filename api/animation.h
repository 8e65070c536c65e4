#pragma once
// "animation": {"frames": [start, end], "fps": 24, "shutter": 0.5}: a scene rendered as frames.
// Frame i's shutter opens at i / fps and stays open shutter / fps (a 180-degree shutter is 0.5);
// objects move by the motion model (renderer/core/motion.h), so frame i is the scene with the
// camera's shutter [i / fps, (i + shutter) / fps] (docs/animation-and-windows.md).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace penumbra::api {

struct Animation {
  int64_t first_frame = 0;  // inclusive, as Blender's frame range
  int64_t last_frame = 0;
  double fps = 24.0;        // frames per second of scene time (> 0)
  double shutter = 0.5;     // fraction of a frame the shutter is open, in [0, 1]
  int64_t frame_count() const { return last_frame - first_frame + 1; }
  bool has_frame(int64_t frame) const { return frame >= first_frame && frame <= last_frame; }
};

// Frame i's shutter in scene time, computed in double precision (the camera stores floats: a
// scene with this shutter written as JSON numbers renders the same bits).
struct FrameShutter {
  double open = 0.0;
  double close = 0.0;
};
FrameShutter frame_shutter(const Animation& animation, int64_t frame);

// The largest |time| any frame's shutter reaches: the motion range objects are checked over.
double animation_time_extent(const Animation& animation);

// "out_####.exr" with frame 17 -> "out_0017.exr": each run of '#' becomes the frame number,
// zero-padded to the run's length (Blender's -o //frame_####); a negative frame keeps its sign
// ahead of the padding ("-017"). Without any '#', the path is returned unchanged.
std::string frame_path(const std::string& pattern, int64_t frame);
bool has_frame_pattern(const std::string& pattern);

}  // namespace penumbra::api
