#pragma once
// Assembling the windows of one frame, rendered apart (RenderSettings::window), into the whole
// image: beauty and output layers. Every pixel must come from exactly one window; anything else
// is an error, never a silently black or doubled pixel (docs/animation-and-windows.md).
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/pixel_window.h"

namespace penumbra {

// One rendered window: `image` and every layer hold window.width() x window.height() pixels.
struct WindowPart {
  std::string name;  // how errors name it (a file name; "part 2")
  PixelWindow window;
  Image image;
  std::vector<ImageLayer> layers;
};

struct MergedImage {
  Image image;
  std::vector<ImageLayer> layers;  // in the order of the first part's layers
};

struct WindowMergeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The width x height image the parts tile. Throws WindowMergeError naming the part(s) at fault
// when a window lies outside the image, two windows overlap (and where), pixels are covered by
// no window (how many, the first, and their bounding box), an image's size is not its window's,
// or the parts do not carry the same layers. Pixel values are copied, never recomputed: a merge
// of windows rendered with uniform sampling is bit-identical to the render of the whole image.
MergedImage merge_windows(const std::vector<WindowPart>& parts, int width, int height);

}  // namespace penumbra
