#include "server/storage/result_files.h"

#include "renderer/io/image_io.h"
#include "renderer/io/layer_io.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::server {

std::string result_key(const std::string& layer, bool blender, const std::string& extension) {
  if (blender) return "blender." + extension;
  return layer.empty() ? extension : layer + "." + extension;
}

const std::vector<std::string>& all_result_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = {"exr", "png", "blender.exr"};
    for (const char* layer : kOutputLayerNames)
      for (const char* ext : {"exr", "png"}) k.push_back(result_key(layer, false, ext));
    for (const char* ext : {"exr", "png"}) k.push_back(result_key(kNoisyLayerName, false, ext));
    return k;
  }();
  return keys;
}

std::string frame_result_key(int frame, const std::string& key) {
  return kFramesKeyPrefix + std::to_string(frame) + "." + key;
}

void write_results(ResultStore& store, const std::string& id, const Image& image,
                   const std::vector<ImageLayer>& layers, const ImageMetadata& metadata,
                   std::optional<int> frame) {
  const auto key = [&](const std::string& k) { return frame ? frame_result_key(*frame, k) : k; };
  // Without layers the EXR is exactly what it was before layers existed (R, G, B).
  store.write(id, key("exr"),
              layers.empty() ? encode_image(image, ImageFormat::kExr, metadata)
                             : encode_layered_exr(image, layers, ExrLayout::kPlain, metadata));
  store.write(id, key("png"), encode_image(image, ImageFormat::kPng, metadata));
  // Only with layers: a job without them would pay a second copy of its EXR on disk for a
  // layout only a compositing or denoising workflow asks for.
  if (!layers.empty())
    store.write(id, key(result_key("", true, "exr")),
                encode_layered_exr(image, layers, ExrLayout::kBlender, metadata));
  for (const ImageLayer& layer : layers)
    for (const ImageFormat f : {ImageFormat::kExr, ImageFormat::kPng})
      store.write(id, key(result_key(layer.name, false, f == ImageFormat::kExr ? "exr" : "png")),
                  encode_layer(layer, image.width, image.height, f, metadata));
}

}  // namespace penumbra::server
