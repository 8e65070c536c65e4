#include "renderer/io/image_reader.h"

#include <OpenImageIO/imageio.h>

#include <cmath>

namespace penumbra {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ImageIoError(path + ": " + reason);
}


// The header of an open image, checked against the limits.
AssetImageInfo check_header(const std::string& path, const OIIO::ImageSpec& spec,
                            const ImageReadLimits& limits) {
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
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
  info.channels = std::min(spec.nchannels, limits.max_channels);
  info.is_float = spec.format.is_floating_point();
  info.is_8bit = spec.format == OIIO::TypeDesc::UINT8;
  return info;
}

std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) fail(path, "cannot read the image: " + OIIO::geterror());
  return in;
}

}  // namespace

AssetImageInfo probe_asset_image(const std::string& path, const ImageReadLimits& limits) {
  return check_header(path, open_image(path)->spec(), limits);
}

AssetImage read_asset_image(const std::string& path, const ImageReadLimits& limits) {
  auto in = open_image(path);
  const AssetImageInfo info = check_header(path, in->spec(), limits);
  AssetImage img;
  img.width = info.width;
  img.height = info.height;
  img.channels = info.channels;
  img.is_float = info.is_float;
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.pixels.data()))
    fail(path, "cannot decode the image: " + in->geterror());
  in->close();
  for (float& v : img.pixels)
    if (!std::isfinite(v)) v = 0.f;
  return img;
}

AssetImage8 read_asset_image_8bit(const std::string& path, const ImageReadLimits& limits) {
  auto in = open_image(path);
  const AssetImageInfo info = check_header(path, in->spec(), limits);
  if (!info.is_8bit) fail(path, "the image does not store 8-bit values");
  AssetImage8 img;
  img.width = info.width;
  img.height = info.height;
  img.channels = info.channels;
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::UINT8, img.pixels.data()))
    fail(path, "cannot decode the image: " + in->geterror());
  in->close();
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
