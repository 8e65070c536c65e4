#pragma once
// An image decoded for texture lookups: linear float texels, row 0 = the image's top row, so
// uv (0, 0) is its top-left corner (glTF, Mitsuba 3 `bitmap`).
#include <string>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/io/image_reader.h"
#include "renderer/textures/texture_desc.h"

namespace penumbra {

class TextureImage {
 public:
  // `texels`: width * height * channels values, channel-interleaved, rows from the top.
  TextureImage(int width, int height, int channels, std::vector<float> texels);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  const float* texel(int x, int y) const {
    return texels_.data() + (size_t(y) * size_t(width_) + size_t(x)) * size_t(channels_);
  }
  int64_t bytes() const { return int64_t(texels_.size() * sizeof(float)); }
  // Mean of one channel over the image (e.g. for an emitter's power estimate).
  float mean(int channel) const;

 private:
  int width_, height_, channels_;
  std::vector<float> texels_;
};

// Reads and decodes an image file (OpenImageIO: PNG, JPEG, EXR, HDR, TIFF, ...), its header
// checked against `limits` before any pixel is decoded; sRGB-encoded values are converted to
// linear here, once (IEC 61966-2-1), so lookups interpolate linear values as Mitsuba 3 does.
// Throws ImageIoError naming the file.
TextureImage load_texture_image(const std::string& path, TextureColorspace colorspace,
                                const ImageReadLimits& limits = {});

}  // namespace penumbra
