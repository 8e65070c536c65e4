#include "renderer/textures/texture_image.h"

#include <utility>

namespace penumbra {

TextureImage::TextureImage(int width, int height, int channels, std::vector<float> texels)
    : width_(width), height_(height), channels_(channels), floats_(std::move(texels)) {}

TextureImage::TextureImage(int width, int height, int channels, std::vector<uint8_t> texels,
                           TextureColorspace colorspace)
    : width_(width), height_(height), channels_(channels), bytes_(std::move(texels)) {
  for (int i = 0; i < 256; ++i) {
    const float v = float(i) / 255.f;
    tables_[0][size_t(i)] = colorspace == TextureColorspace::kSrgb ? srgb_to_linear(v) : v;
    tables_[1][size_t(i)] = v;
  }
  // The alpha channel of grey + alpha (YA) and RGBA images is linear.
  for (int c = 0; c < 4; ++c)
    table_of_[size_t(c)] = (channels == 2 && c == 1) || (channels == 4 && c == 3) ? 1 : 0;
}

float TextureImage::mean(int channel) const {
  double sum = 0.0;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) sum += value(x, y, channel);
  const double n = double(width_) * double(height_);
  return n > 0 ? float(sum / n) : 0.f;
}

TextureImage load_texture_image(const std::string& path, TextureColorspace colorspace,
                                const ImageReadLimits& limits) {
  if (probe_asset_image(path, limits).is_8bit) {
    AssetImage8 image = read_asset_image_8bit(path, limits);
    return TextureImage(image.width, image.height, image.channels, std::move(image.pixels),
                        colorspace);
  }
  AssetImage image = read_asset_image(path, limits);
  if (colorspace == TextureColorspace::kSrgb) srgb_to_linear_in_place(image);
  return TextureImage(image.width, image.height, image.channels, std::move(image.pixels));
}

}  // namespace penumbra
