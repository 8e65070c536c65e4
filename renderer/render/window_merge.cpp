#include "renderer/render/window_merge.h"

#include <algorithm>
#include <cstdint>
#include <limits>

namespace penumbra {
namespace {

std::string window_text(const PixelWindow& w) {
  return "[" + std::to_string(w.x0) + ", " + std::to_string(w.y0) + ", " + std::to_string(w.x1) + ", " +
         std::to_string(w.y1) + ")";
}

std::string pixel_text(int x, int y) { return "(" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

// The part's window and sizes are consistent with the image and with the first part.
void check_part(const WindowPart& part, const WindowPart& first, int width, int height) {
  const PixelWindow& w = part.window;
  if (!w.fits(width, height))
    throw WindowMergeError(part.name + ": window " + window_text(w) + " is empty or not inside the " +
                           std::to_string(width) + "x" + std::to_string(height) + " image");
  const size_t pixels = size_t(w.pixel_count());
  if (part.image.width != w.width() || part.image.height != w.height() || part.image.rgb.size() != 3 * pixels)
    throw WindowMergeError(part.name + ": image of " + std::to_string(part.image.width) + "x" +
                           std::to_string(part.image.height) + " pixels does not fill its window " +
                           window_text(w));
  if (part.layers.size() != first.layers.size())
    throw WindowMergeError(part.name + ": has " + std::to_string(part.layers.size()) + " output layers, " +
                           first.name + " has " + std::to_string(first.layers.size()) +
                           " (render every window with the same outputs)");
  for (size_t i = 0; i < part.layers.size(); ++i) {
    const ImageLayer &a = part.layers[i], &b = first.layers[i];
    if (a.name != b.name || a.channels != b.channels || a.kind != b.kind)
      throw WindowMergeError(part.name + ": output layer " + std::to_string(i) + " is \"" + a.name + "\", " +
                             first.name + " has \"" + b.name + "\" (render every window with the same outputs)");
    if (a.channels <= 0 || a.data.size() != pixels * size_t(a.channels))
      throw WindowMergeError(part.name + ": output layer \"" + a.name + "\" does not fill its window");
  }
}

}  // namespace

MergedImage merge_windows(const std::vector<WindowPart>& parts, int width, int height) {
  if (width <= 0 || height <= 0) throw WindowMergeError("the merged image has no pixels");
  if (parts.empty()) throw WindowMergeError("no windows to merge");
  for (const WindowPart& part : parts) check_part(part, parts.front(), width, height);

  // Which part wrote each pixel (none yet: max). The windows fit in the image, so this and the
  // images below are bounded by the image the caller asked for.
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> owner(size_t(width) * size_t(height), kNone);
  for (size_t p = 0; p < parts.size(); ++p) {
    const PixelWindow& w = parts[p].window;
    for (int y = w.y0; y < w.y1; ++y)
      for (int x = w.x0; x < w.x1; ++x) {
        uint32_t& o = owner[size_t(y) * width + x];
        if (o != kNone)
          throw WindowMergeError(parts[p].name + ": window " + window_text(w) + " overlaps " +
                                 parts[o].name + "'s " + window_text(parts[o].window) + " at pixel " +
                                 pixel_text(x, y) + "; every pixel must be rendered exactly once");
        o = uint32_t(p);
      }
  }
  int64_t missing = 0;
  PixelWindow hole{width, height, 0, 0};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (owner[size_t(y) * width + x] == kNone) {
        ++missing;
        hole = {std::min(hole.x0, x), std::min(hole.y0, y), std::max(hole.x1, x + 1), std::max(hole.y1, y + 1)};
      }
  if (missing)
    throw WindowMergeError(std::to_string(missing) + " pixels are in no window (all inside " +
                           window_text(hole) + " of the " + std::to_string(width) + "x" +
                           std::to_string(height) + " image); every pixel must be rendered exactly once");

  MergedImage out;
  out.image = Image(width, height);
  for (const ImageLayer& l : parts.front().layers)
    out.layers.push_back({l.name, l.kind, l.channels, std::vector<float>(size_t(width) * height * l.channels)});
  for (const WindowPart& part : parts) {
    const PixelWindow& w = part.window;
    for (int y = 0; y < w.height(); ++y) {
      const size_t src = size_t(y) * w.width(), dst = size_t(w.y0 + y) * width + w.x0;
      std::copy_n(&part.image.rgb[3 * src], 3 * size_t(w.width()), &out.image.rgb[3 * dst]);
      for (size_t l = 0; l < part.layers.size(); ++l) {
        const size_t c = size_t(part.layers[l].channels);
        std::copy_n(&part.layers[l].data[c * src], c * w.width(), &out.layers[l].data[c * dst]);
      }
    }
  }
  return out;
}

}  // namespace penumbra
