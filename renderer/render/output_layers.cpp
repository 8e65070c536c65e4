#include "renderer/render/output_layers.h"

namespace penumbra {

LayerFilm::LayerFilm(int width, int height, uint32_t outputs, const vec3& view_origin,
                     const vec3& view_axis)
    : width_(width),
      height_(height),
      outputs_(outputs),
      view_origin_(view_origin),
      view_axis_(view_axis),
      pixels_(size_t(width) * size_t(height)) {}

std::vector<ImageLayer> LayerFilm::resolve() const {
  std::vector<ImageLayer> layers;
  const size_t count = pixels_.size();
  if (outputs_ & kOutputAlbedo) {
    ImageLayer layer{kOutputLayerNames[0], ImageLayer::Kind::kColor, 3, std::vector<float>(3 * count, 0.f)};
    for (size_t i = 0; i < count; ++i)
      if (const Pixel& p = pixels_[i]; p.n)
        for (int c = 0; c < 3; ++c) layer.data[3 * i + c] = float(p.albedo[c] / p.n);
    layers.push_back(std::move(layer));
  }
  if (outputs_ & kOutputNormal) {
    ImageLayer layer{kOutputLayerNames[1], ImageLayer::Kind::kVector, 3, std::vector<float>(3 * count, 0.f)};
    for (size_t i = 0; i < count; ++i)
      if (const Pixel& p = pixels_[i]; p.n)
        for (int c = 0; c < 3; ++c) layer.data[3 * i + c] = float(p.normal[c] / p.n);
    layers.push_back(std::move(layer));
  }
  if (outputs_ & kOutputDepth) {
    ImageLayer layer{kOutputLayerNames[2], ImageLayer::Kind::kDepth, 1, std::vector<float>(count, kBackgroundDepth)};
    for (size_t i = 0; i < count; ++i)
      if (const Pixel& p = pixels_[i]; p.hits) layer.data[i] = float(p.depth / p.hits);
    layers.push_back(std::move(layer));
  }
  return layers;
}

}  // namespace penumbra
