#pragma once
// OpenEXR encoding through the OpenEXR library: linear float RGB, ZIP compression, metadata as
// string attributes. Like png_writer.h, it keeps OpenImageIO off the render output path.
#include <cstdint>
#include <vector>

#include "renderer/core/image.h"

namespace penumbra {

// `rgb` holds width * height * 3 floats, rows top to bottom. Throws ImageIoError.
std::vector<uint8_t> encode_exr(const float* rgb, int width, int height,
                                const ImageMetadata& metadata);

}  // namespace penumbra
