#pragma once
// PNG encoding through libpng: 8-bit sRGB RGB, metadata as tEXt chunks. The render output path
// must not need OpenImageIO (its 250 shared libraries cost a CLI run 0.3 s; docs/design-notes.md).
#include <cstdint>
#include <vector>

#include "renderer/core/image.h"

namespace penumbra {

// `rgb8` holds width * height * 3 bytes, rows top to bottom. Throws ImageIoError.
// `srgb` false marks the bytes as data (a normal map, a depth ramp): no sRGB/gAMA chunks, so
// tools read the values as they are.
std::vector<uint8_t> encode_png(const uint8_t* rgb8, int width, int height,
                                const ImageMetadata& metadata, bool srgb = true);

}  // namespace penumbra
