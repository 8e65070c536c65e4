// libFuzzer target: arbitrary bytes read as a window of a frame (renderer/io/exr_window_file.h),
// the files `penumbra merge` reads from other machines. Bad files must give ImageIoError, never a
// crash, an unbounded allocation or undefined behaviour; a file that reads must describe a window
// inside its frame, with finite pixels, and merge (alone, it must fill or fail cleanly).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "renderer/io/exr_window_file.h"
#include "renderer/io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<uint8_t> bytes(data, data + size);
  penumbra::ExrWindowLimits limits;
  limits.max_pixels = 256 * 256;  // small caps keep each input fast
  try {
    const penumbra::ExrWindowFile f = penumbra::read_exr_window("fuzz.exr", bytes, limits);
    if (!f.part.window.fits(f.display.width(), f.display.height())) std::abort();
    for (float v : f.part.image.rgb)
      if (!std::isfinite(v)) std::abort();
    try {
      penumbra::merge_windows({f.part}, f.display.width(), f.display.height());
    } catch (const penumbra::WindowMergeError&) {
      // A window smaller than its frame leaves a hole: an error, as it must be.
    }
  } catch (const penumbra::ImageIoError&) {
  }
  return 0;
}
