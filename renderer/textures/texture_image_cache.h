#pragma once
// The decoded images of one scene build: each distinct (file, colorspace) decoded once, however
// many materials and emitters use it, within the build's TextureLimits.
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "renderer/textures/texture_image.h"

namespace penumbra {

class TextureImageCache {
 public:
  explicit TextureImageCache(const TextureLimits& limits = {}) : limits_(limits) {}

  // The image, decoded on first use. Throws ImageIoError naming the file if it cannot be read or
  // exceeds the limits (per image, or the build's total with it).
  const TextureImage& get(const std::string& path, TextureColorspace colorspace);

  size_t size() const { return images_.size(); }
  int64_t bytes() const { return bytes_; }

 private:
  TextureLimits limits_;
  std::map<std::pair<std::string, TextureColorspace>, std::unique_ptr<TextureImage>> images_;
  int64_t bytes_ = 0;
};

}  // namespace penumbra
