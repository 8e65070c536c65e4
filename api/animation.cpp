#include "api/animation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>


namespace penumbra::api {

FrameShutter frame_shutter(const Animation& animation, int64_t frame) {
  const double i = double(frame);
  return {i / animation.fps, (i + animation.shutter) / animation.fps};
}

double animation_time_extent(const Animation& animation) {
  const FrameShutter first = frame_shutter(animation, animation.first_frame);
  const FrameShutter last = frame_shutter(animation, animation.last_frame);
  return std::max({std::abs(first.open), std::abs(first.close), std::abs(last.open), std::abs(last.close)});
}

bool has_frame_pattern(const std::string& pattern) { return pattern.find('#') != std::string::npos; }

std::string frame_path(const std::string& pattern, int64_t frame) {
  std::string out;
  // The magnitude in unsigned arithmetic: -INT64_MIN does not fit an int64_t.
  const uint64_t magnitude = frame < 0 ? uint64_t(0) - uint64_t(frame) : uint64_t(frame);
  const std::string digits = std::to_string(magnitude);
  for (size_t i = 0; i < pattern.size();) {
    if (pattern[i] != '#') {
      out += pattern[i++];
      continue;
    }
    size_t run = 0;
    while (i + run < pattern.size() && pattern[i + run] == '#') ++run;
    if (frame < 0) out += '-';
    if (digits.size() < run) out.append(run - digits.size(), '0');
    out += digits;
    i += run;
  }
  return out;
}

}  // namespace penumbra::api
