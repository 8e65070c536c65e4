#pragma once
// A rectangle of an image's pixels: the part of a frame one render produces when a frame is
// split across machines (docs/animation-and-windows.md).
#include <cstdint>

namespace penumbra {

// Pixels [x0, x1) x [y0, y1) of a width x height image, x right and y down from the top-left
// pixel, as OpenImageIO's ROI (xbegin, xend) and an EXR data window of (x0, y0)-(x1 - 1, y1 - 1).
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  int64_t pixel_count() const { return int64_t(width()) * int64_t(height()); }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  // Inside a width x height image and not empty.
  bool fits(int image_width, int image_height) const {
    return !empty() && x0 >= 0 && y0 >= 0 && x1 <= image_width && y1 <= image_height;
  }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  bool operator==(const PixelWindow&) const = default;
};

}  // namespace penumbra
