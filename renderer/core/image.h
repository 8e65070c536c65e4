#pragma once
// A linear-RGB float image, row-major from the top-left pixel.
#include <string>
#include <utility>
#include <vector>

namespace penumbra {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // width * height * 3

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0.f) {}
  float* pixel(int x, int y) { return &rgb[(size_t(y) * width + x) * 3]; }
  const float* pixel(int x, int y) const { return &rgb[(size_t(y) * width + x) * 3]; }
};

// An output layer beside the beauty image (renderer/render/output_layers.h): `channels` floats
// per pixel, row-major from the top-left pixel. The kind decides how writers encode it
// (docs/output-layers.md): a colour, a vector (normal), or a depth.
struct ImageLayer {
  enum class Kind { kColor, kVector, kDepth };
  std::string name;  // "albedo", "normal", "depth"
  Kind kind = Kind::kColor;
  int channels = 3;  // 3, or 1 for depth
  std::vector<float> data;
};

// Name/value pairs written into the file header where the format allows it (EXR attributes).
using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

}  // namespace penumbra
