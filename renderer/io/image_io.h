#pragma once
// Image encoding through OpenImageIO: EXR (linear half/float) and PNG (sRGB, 8-bit, clamped).
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/core/image.h"

namespace penumbra {

enum class ImageFormat { kPng, kExr };

struct ImageIoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// IEC 61966-2-1: linear [0, 1] to the sRGB-encoded value (clamped; NaN gives 0).
float linear_to_srgb(float v);

// Format from a file name's extension (".png", ".exr", case-insensitive); throws ImageIoError.
ImageFormat image_format_from_path(const std::string& path);
// Encodes in memory. Non-finite values are written as 0 (they should never reach here).
std::vector<uint8_t> encode_image(const Image& image, ImageFormat format,
                                  const ImageMetadata& metadata = {});
// Writes atomically: a temporary file in the same directory, then rename.
void write_image_file(const std::string& path, const Image& image,
                      const ImageMetadata& metadata = {});
// The bytes to `path` in the same way (an encoded image made elsewhere, a layer file).
void write_file_atomically(const std::string& path, const std::vector<uint8_t>& bytes);
// Reads any format OpenImageIO knows into linear RGB float (PNG is decoded from sRGB).
Image read_image_file(const std::string& path);

}  // namespace penumbra
