#include "renderer/io/image_reader.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "renderer/core/row_blocks.h"
#include "renderer/io/exr_reader.h"
#include "renderer/io/hdr_reader.h"
#include "renderer/io/jpeg_reader.h"
#include "renderer/io/oiio_module.h"
#include "renderer/io/png_reader.h"

namespace penumbra {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ImageIoError(path + ": " + reason);
}


// The header of an open image, checked against the limits.
AssetImageInfo check_header(const std::string& path, const PenumbraImageSpec& spec,
                            const ImageReadLimits& limits) {
  if (spec.width <= 0 || spec.height <= 0 || spec.channels <= 0)
    fail(path, "the image has no pixels");
  if (spec.width > limits.max_dimension || spec.height > limits.max_dimension)
    fail(path, "the image is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                   " pixels; at most " + std::to_string(limits.max_dimension) + " per side");
  const int64_t pixels = int64_t(spec.width) * spec.height;
  if (pixels > limits.max_pixels)
    fail(path, "the image has " + std::to_string(pixels) + " pixels; at most " +
                   std::to_string(limits.max_pixels));
  if (spec.depth > 1) fail(path, "volume images are not supported");
  AssetImageInfo info;
  info.width = spec.width;
  info.height = spec.height;
  info.channels = std::min(spec.channels, limits.max_channels);
  info.is_float = spec.is_float != 0;
  info.is_8bit = spec.is_uint8 != 0;
  return info;
}

// The reader of a source: PNG through libpng (png_reader.h), the common form of EXR through
// OpenEXR (exr_reader.h), Radiance HDR here (hdr_reader.h), JPEG through libjpeg-turbo
// (jpeg_reader.h), anything else (and what those leave) through the OpenImageIO plug-in, loaded
// on first use (oiio_module.h). Errors name the path (for an image in memory, its name).
std::unique_ptr<AssetDecoder> open_decoder(const ImageSource& source) {
  const SourceHead head = read_source_head(source);
  std::unique_ptr<AssetDecoder> decoder;
  if (has_png_signature(head))
    decoder = open_png(source);
  else if (has_exr_signature(head))
    decoder = open_exr(source);  // null: an EXR of a form left to the plug-in
  else if (has_hdr_signature(head))
    decoder = open_hdr(source);  // null: an orientation or XYZE left to the plug-in
  else if (has_jpeg_signature(head))
    decoder = open_jpeg(source);  // null: CMYK or YCCK, left to the plug-in
  if (!decoder) decoder = open_plugin_image(source);
  return decoder;
}

}  // namespace

AssetImageInfo probe_asset_image(const ImageSource& source, const ImageReadLimits& limits) {
  return check_header(source.path, open_decoder(source)->spec(), limits);
}

AssetImage read_asset_image(const ImageSource& source, const ImageReadLimits& limits) {
  const std::string& path = source.path;
  const auto in = open_decoder(source);
  const AssetImageInfo info = check_header(path, in->spec(), limits);
  AssetImage img;
  img.width = info.width;
  img.height = info.height;
  img.channels = info.channels;
  img.is_float = info.is_float;
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  in->read(img.channels, img.pixels.data());
  // Non-finite values to 0, in blocks on all cores (an 8192 x 4096 map is 100M values); by the
  // exponent's bits, branch-free, so that the loop vectorises.
  for_row_blocks(img.pixels.size(), kRowBlockCells, [&](size_t begin, size_t end) {
    float* v = img.pixels.data();
    for (size_t i = begin; i < end; ++i)
      v[i] = (std::bit_cast<uint32_t>(v[i]) & 0x7f800000u) == 0x7f800000u ? 0.f : v[i];
  });
  return img;
}

AssetImage8 read_asset_image_8bit(const ImageSource& source, const ImageReadLimits& limits) {
  const std::string& path = source.path;
  const auto in = open_decoder(source);
  const AssetImageInfo info = check_header(path, in->spec(), limits);
  if (!info.is_8bit) fail(path, "the image does not store 8-bit values");
  AssetImage8 img;
  img.width = info.width;
  img.height = info.height;
  img.channels = info.channels;
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  in->read(img.channels, img.pixels.data());
  return img;
}

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

void srgb_to_linear_in_place(AssetImage& image) {
  // RGB and RGBA: the first three; grey (Y) and grey + alpha (YA): the first only.
  const int color_channels = image.channels >= 3 ? 3 : 1;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    if (int(i % size_t(image.channels)) < color_channels) image.pixels[i] = srgb_to_linear(image.pixels[i]);
}

}  // namespace penumbra
