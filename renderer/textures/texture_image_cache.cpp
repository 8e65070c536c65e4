#include "renderer/textures/texture_image_cache.h"

namespace penumbra {

const TextureImage& TextureImageCache::get(const std::string& path, TextureColorspace colorspace) {
  auto key = std::make_pair(path, colorspace);
  if (auto it = images_.find(key); it != images_.end()) return *it->second;
  ImageReadLimits read_limits;
  read_limits.max_pixels = limits_.max_pixels;
  auto image = std::make_unique<TextureImage>(load_texture_image(path, colorspace, read_limits));
  if (bytes_ + image->bytes() > limits_.max_bytes)
    throw ImageIoError(path + ": the scene's textures would take " +
                       std::to_string(bytes_ + image->bytes()) + " bytes decoded; at most " +
                       std::to_string(limits_.max_bytes));
  bytes_ += image->bytes();
  return *images_.emplace(std::move(key), std::move(image)).first->second;
}

}  // namespace penumbra
