#pragma once
// An image decoded for texture lookups: linear values, row 0 = the image's top row, so uv (0, 0)
// is its top-left corner (glTF, Mitsuba 3 `bitmap`).
//
// 8-bit images (PNG, JPEG, ...) keep their bytes and decode each texel as it is fetched, through a
// 256-entry table per channel (sRGB or linear; alpha always linear), as Mitsuba 3.9's bitmap
// does; other images are stored as linear floats. The values are the same either way (the table
// holds exactly what decoding at load would give), but the 8-bit store takes a quarter of the
// memory and of the cache: lookups into large textures are bound by memory latency
// (docs/design-notes.md, "Textures").
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/io/image_reader.h"
#include "renderer/textures/texture_desc.h"

namespace penumbra {

class TextureImage {
 public:
  // `texels`: width * height * channels linear values, channel-interleaved, rows from the top.
  TextureImage(int width, int height, int channels, std::vector<float> texels);
  // 8-bit stored values; the colour channels decode as `colorspace` says, alpha linearly.
  TextureImage(int width, int height, int channels, std::vector<uint8_t> texels,
               TextureColorspace colorspace);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool is_8bit() const { return !bytes_.empty(); }

  // Channels [first, first + count) of texel (x, y), linear, into out.
  void fetch(int x, int y, int first, int count, float* out) const {
    const size_t i = (size_t(y) * size_t(width_) + size_t(x)) * size_t(channels_) + size_t(first);
    if (bytes_.empty()) {
      for (int c = 0; c < count; ++c) out[c] = floats_[i + size_t(c)];
    } else {
      for (int c = 0; c < count; ++c) out[c] = tables_[table_of_[first + c]][bytes_[i + size_t(c)]];
    }
  }
  float value(int x, int y, int channel) const {
    float v;
    fetch(x, y, channel, 1, &v);
    return v;
  }
  int64_t bytes() const { return int64_t(floats_.size() * sizeof(float) + bytes_.size()); }
  // Mean of one channel over the image (e.g. for an emitter's power estimate).
  float mean(int channel) const;

 private:
  int width_, height_, channels_;
  std::vector<float> floats_;
  std::vector<uint8_t> bytes_;
  std::array<std::array<float, 256>, 2> tables_{};  // [0]: colour channels, [1]: alpha
  std::array<uint8_t, 4> table_of_{};               // per channel: which table
};

// Reads and decodes an image file (OpenImageIO: PNG, JPEG, EXR, HDR, TIFF, ...), its header
// checked against `limits` before any pixel is decoded; sRGB-encoded values become linear (IEC
// 61966-2-1) before any interpolation, so lookups interpolate linear values as Mitsuba 3 does.
// Throws ImageIoError naming the file.
TextureImage load_texture_image(const std::string& path, TextureColorspace colorspace,
                                const ImageReadLimits& limits = {});

}  // namespace penumbra
