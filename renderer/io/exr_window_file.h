#pragma once
// Reading back a window of a frame written as an EXR (penumbra render --window ... -o part.exr):
// its data window inside the display window, and its channels as the beauty image and the
// output layers, for merging (renderer/render/window_merge.h).
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/core/pixel_window.h"
#include "renderer/io/layer_io.h"
#include "renderer/render/window_merge.h"

namespace penumbra {

struct ExrWindowLimits {
  int64_t max_pixels = int64_t(8192) * 8192;  // of the display window (the whole frame)
  int max_channels = 64;
};

struct ExrWindowFile {
  PixelWindow display;  // the whole frame; (0, 0) at its top-left
  WindowPart part;      // the data window's pixels; part.name = the path
  ExrLayout layout = ExrLayout::kPlain;
  ImageMetadata metadata;  // the header's string attributes
};

// Reads the channels penumbra writes (encode_layered_exr, either layout: R, G, B or
// ViewLayer.Combined.R/G/B, and the albedo, normal, depth layers) as float. Throws ImageIoError
// naming the file when it cannot be read, is not such an image, its display window does not start
// at (0, 0), its data window is not inside the display window, or it is over the limits (checked
// from the header, before any pixel is decoded).
ExrWindowFile read_exr_window(const std::string& path, const ExrWindowLimits& limits = {});
// The same from encoded bytes in memory; `name` names them in errors.
ExrWindowFile read_exr_window(const std::string& name, const std::vector<uint8_t>& bytes,
                              const ExrWindowLimits& limits = {});

}  // namespace penumbra
