#pragma once
// OpenEXR encoding through the OpenEXR library: linear float RGB, ZIP compression, metadata as
// string attributes. Like png_writer.h, it keeps OpenImageIO off the render output path.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/pixel_window.h"

namespace penumbra {

// `rgb` holds width * height * 3 floats, rows top to bottom. Throws ImageIoError.
std::vector<uint8_t> encode_exr(const float* rgb, int width, int height,
                                const ImageMetadata& metadata);

// One float channel of an EXR: its full name ("R", "albedo.R", "ViewLayer.Combined.A") and its
// first pixel's value, the next pixel's `x_stride` bytes on, rows `x_stride * width` apart.
struct ExrChannel {
  std::string name;
  const float* base = nullptr;
  std::size_t x_stride = sizeof(float);
};
// Any number of channels in one scan-line part (OpenEXR's multi-layer convention: "layer.channel"
// names; readers group them by the text before the last dot). Throws ImageIoError.
// With `display`, the width x height pixels are the data window `data` of a display window of
// display.width() x display.height() (a crop of a bigger frame, as Nuke and Blender write them;
// data's size must be width x height); without, data and display window are the whole image.
std::vector<uint8_t> encode_exr_channels(const std::vector<ExrChannel>& channels, int width,
                                         int height, const ImageMetadata& metadata,
                                         const PixelWindow* data = nullptr,
                                         const PixelWindow* display = nullptr);

}  // namespace penumbra
