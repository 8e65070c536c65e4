#pragma once
// Reading image assets (textures, environment maps) from untrusted files: the header is checked
// against explicit limits before any pixel is decoded, so a file that claims 100k x 100k pixels
// costs nothing; every error names the file.
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/io/image_io.h"

namespace penumbra {

struct ImageReadLimits {
  int64_t max_pixels = int64_t(16384) * 8192;  // per image (a 16k x 8k environment map)
  int max_dimension = 65536;                   // per side
  int max_channels = 4;                        // channels kept (more are dropped, not an error)
};

// Pixels as stored, converted to float, channel-interleaved, row 0 = the image's top row.
struct AssetImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  bool is_float = false;  // the file stores floating-point values (EXR, HDR, float TIFF):
                          // linear by convention; integer formats are usually sRGB-encoded
  std::vector<float> pixels;
  size_t bytes() const { return pixels.size() * sizeof(float); }
};

// What an image file's header says, checked against the limits: nothing is decoded.
struct AssetImageInfo {
  int width = 0;
  int height = 0;
  int channels = 0;       // channels that would be kept (at most limits.max_channels)
  bool is_float = false;  // as AssetImage::is_float
  bool is_8bit = false;   // stored as 8-bit integers (PNG, JPEG, 8-bit TIFF, ...)
};

// Opens the file and checks its header (size, channels, not a volume) without decoding a pixel.
// Throws ImageIoError ("<path>: <reason>") for unreadable files, unknown formats, and images
// over the limits.
AssetImageInfo probe_asset_image(const std::string& path, const ImageReadLimits& limits = {});

// Throws ImageIoError ("<path>: <reason>") for unreadable files, unknown formats, and images
// over the limits. Non-finite float pixels are replaced by 0 (a NaN texel would poison every
// image that samples it).
AssetImage read_asset_image(const std::string& path, const ImageReadLimits& limits = {});

// The stored 8-bit values of an image whose header says it holds 8-bit integers (is_8bit), not
// converted: a quarter of the float memory. Throws ImageIoError as read_asset_image, and for an
// image that is not 8-bit.
struct AssetImage8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<uint8_t> pixels;  // channel-interleaved, row 0 = the image's top row
};
AssetImage8 read_asset_image_8bit(const std::string& path, const ImageReadLimits& limits = {});

// IEC 61966-2-1: one sRGB-encoded value in [0, 1] to linear.
float srgb_to_linear(float v);

// IEC 61966-2-1: sRGB-encoded values in [0, 1] to linear, in place, on the colour channels: the
// first three of RGB(A), the first of a grey image (Y, YA); alpha is linear already.
void srgb_to_linear_in_place(AssetImage& image);

}  // namespace penumbra
