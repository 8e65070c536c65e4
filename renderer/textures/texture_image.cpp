#include "renderer/textures/texture_image.h"

#include <utility>

namespace penumbra {

TextureImage::TextureImage(int width, int height, int channels, std::vector<float> texels)
    : width_(width), height_(height), channels_(channels), texels_(std::move(texels)) {}

float TextureImage::mean(int channel) const {
  double sum = 0.0;
  const size_t n = size_t(width_) * size_t(height_);
  for (size_t i = 0; i < n; ++i) sum += texels_[i * size_t(channels_) + size_t(channel)];
  return n > 0 ? float(sum / double(n)) : 0.f;
}

TextureImage load_texture_image(const std::string& path, TextureColorspace colorspace,
                                const ImageReadLimits& limits) {
  AssetImage image = read_asset_image(path, limits);
  if (colorspace == TextureColorspace::kSrgb) srgb_to_linear_in_place(image);
  return TextureImage(image.width, image.height, image.channels, std::move(image.pixels));
}

}  // namespace penumbra
