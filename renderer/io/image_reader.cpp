#include "renderer/io/image_reader.h"

#include <algorithm>
#include <cmath>

#include "renderer/io/oiio_module.h"

namespace penumbra {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ImageIoError(path + ": " + reason);
}

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

AssetImage read_asset_image(const std::string& path, const ImageReadLimits& limits) {
  const auto in = open_plugin_image(path);
  const PenumbraImageSpec spec = in->spec();
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
  AssetImage img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = std::min(spec.channels, limits.max_channels);
  img.is_float = spec.is_float != 0;
  img.pixels.resize(size_t(pixels) * size_t(img.channels));
  in->read(img.channels, img.pixels.data());
  for (float& v : img.pixels)
    if (!std::isfinite(v)) v = 0.f;
  return img;
}

void srgb_to_linear_in_place(AssetImage& image) {
  const int color_channels = std::min(image.channels, 3);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    if (int(i % size_t(image.channels)) < color_channels) image.pixels[i] = srgb_to_linear(image.pixels[i]);
}

}  // namespace penumbra
