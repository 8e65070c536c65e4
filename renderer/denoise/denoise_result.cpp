#include "renderer/denoise/denoise_result.h"

#include <algorithm>
#include <chrono>

#include "renderer/denoise/oidn_denoiser.h"

namespace penumbra {
namespace {

const ImageLayer* find_layer(const std::vector<ImageLayer>& layers, const char* name) {
  for (const ImageLayer& l : layers)
    if (l.name == name) return &l;
  return nullptr;
}

bool requested_layer(uint32_t requested, const std::string& name) {
  for (int i = 0; i < kOutputLayerCount; ++i)
    if (name == kOutputLayerNames[i]) return (requested & (1u << i)) != 0;
  return true;  // not a guide: keep
}

}  // namespace

void denoise_result(uint32_t requested, RenderResult* result) {
  const auto start = std::chrono::steady_clock::now();
  RenderStats& st = result->stats;
  const Image& image = result->image;
  const ImageLayer* albedo = find_layer(result->layers, kOutputLayerNames[0]);
  const ImageLayer* normal = find_layer(result->layers, kOutputLayerNames[1]);
  std::string error;
  auto denoised = denoise({image.width, image.height, image.rgb.data(),
                           albedo ? albedo->data.data() : nullptr,
                           normal ? normal->data.data() : nullptr},
                          &error);
  if (denoised) {
    ImageLayer noisy{kNoisyLayerName, ImageLayer::Kind::kColor, 3, std::move(result->image.rgb)};
    result->image.rgb = std::move(*denoised);
    result->layers.push_back(std::move(noisy));
    st.denoised = true;
  } else {
    st.denoise_error = error;
  }
  result->layers.erase(std::remove_if(result->layers.begin(), result->layers.end(),
                                      [&](const ImageLayer& l) {
                                        return !requested_layer(requested, l.name);
                                      }),
                       result->layers.end());
  st.denoise_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace penumbra
