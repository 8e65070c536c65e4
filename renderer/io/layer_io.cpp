#include "renderer/io/layer_io.h"

#include <algorithm>
#include <cmath>

#include "renderer/io/exr_writer.h"
#include "renderer/io/png_writer.h"
#include "renderer/render/output_layers.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {
namespace {

std::vector<std::string> plain_channels(const ImageLayer& layer) {
  switch (layer.kind) {
    case ImageLayer::Kind::kColor: return {"R", "G", "B"};
    case ImageLayer::Kind::kVector: return {"X", "Y", "Z"};
    case ImageLayer::Kind::kDepth: return {"Z"};
  }
  return {};
}

// Blender's pass names (RE_PASSNAME_* in its render_result code): the albedo is the one its
// denoiser reads, "Denoising Albedo".
std::string blender_pass(const ImageLayer& layer) {
  // The image before denoising: Blender keeps it as "Noisy Image" when it denoises.
  if (layer.name == kNoisyLayerName) return "Noisy Image";
  switch (layer.kind) {
    case ImageLayer::Kind::kColor: return "Denoising Albedo";
    case ImageLayer::Kind::kVector: return "Normal";
    case ImageLayer::Kind::kDepth: return "Depth";
  }
  return layer.name;
}

constexpr const char* kBlenderViewLayer = "ViewLayer";

std::vector<float> finite_copy(const std::vector<float>& v) {
  std::vector<float> out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = std::isfinite(v[i]) ? v[i] : 0.f;
  return out;
}

uint8_t to_byte(float v) { return uint8_t(std::lround(std::clamp(v, 0.f, 1.f) * 255.f)); }

}  // namespace

std::vector<std::string> exr_channel_names(const ImageLayer& layer, ExrLayout layout) {
  std::vector<std::string> names = plain_channels(layer);
  const std::string prefix = layout == ExrLayout::kBlender
                                 ? std::string(kBlenderViewLayer) + "." + blender_pass(layer) + "."
                                 : layer.name + ".";
  for (std::string& n : names) n = prefix + n;
  return names;
}

std::vector<uint8_t> encode_layered_exr(const Image& beauty, const std::vector<ImageLayer>& layers,
                                        ExrLayout layout, const ImageMetadata& metadata,
                                        const PixelWindow* data_window, const PixelWindow* display_window) {
  const int w = beauty.width, h = beauty.height;
  const size_t pixels = size_t(w) * size_t(h);
  std::vector<std::vector<float>> data;  // finite copies, alive until encoded
  data.reserve(layers.size() + 1);
  data.push_back(finite_copy(beauty.rgb));
  std::vector<ExrChannel> channels;
  const std::string combined =
      layout == ExrLayout::kBlender ? std::string(kBlenderViewLayer) + ".Combined." : "";
  for (int c = 0; c < 3; ++c)
    channels.push_back({combined + "RGB"[c], data[0].data() + c, 3 * sizeof(float)});
  if (layout == ExrLayout::kBlender) {
    data.push_back(std::vector<float>(pixels, 1.f));  // opaque: every pixel is rendered
    channels.push_back({combined + "A", data.back().data(), sizeof(float)});
  }
  for (const ImageLayer& layer : layers) {
    if (layer.data.size() != pixels * size_t(layer.channels))
      throw ImageIoError("cannot encode image: layer " + layer.name + " has the wrong size");
    data.push_back(finite_copy(layer.data));
    const std::vector<std::string> names = exr_channel_names(layer, layout);
    for (int c = 0; c < layer.channels; ++c)
      channels.push_back({names[size_t(c)], data.back().data() + c, size_t(layer.channels) * sizeof(float)});
  }
  ImageMetadata meta = metadata;
  // Blender writes this attribute into its own multi-layer files and looks for it on reading.
  if (layout == ExrLayout::kBlender) meta.emplace_back("BlenderMultiChannel", "Blender V2.55.1 and newer");
  return encode_exr_channels(channels, w, h, meta, data_window, display_window);
}

std::vector<uint8_t> encode_layer(const ImageLayer& layer, int width, int height,
                                  ImageFormat format, const ImageMetadata& metadata,
                                  const PixelWindow* data_window, const PixelWindow* display_window) {
  const size_t pixels = size_t(width) * size_t(height);
  if (layer.data.size() != pixels * size_t(layer.channels))
    throw ImageIoError("cannot encode image: layer " + layer.name + " has the wrong size");
  if (format == ImageFormat::kExr) {
    const std::vector<float> data = finite_copy(layer.data);
    const std::vector<std::string> names = plain_channels(layer);
    std::vector<ExrChannel> channels;
    for (int c = 0; c < layer.channels; ++c)
      channels.push_back({names[size_t(c)], data.data() + c, size_t(layer.channels) * sizeof(float)});
    return encode_exr_channels(channels, width, height, metadata, data_window, display_window);
  }
  std::vector<uint8_t> bytes(pixels * 3);
  switch (layer.kind) {
    case ImageLayer::Kind::kColor:
      for (size_t i = 0; i < pixels * 3; ++i) bytes[i] = to_byte(linear_to_srgb(layer.data[i]));
      return encode_png(bytes.data(), width, height, metadata, true);
    case ImageLayer::Kind::kVector:
      for (size_t i = 0; i < pixels * 3; ++i)
        bytes[i] = to_byte(std::isfinite(layer.data[i]) ? layer.data[i] * 0.5f + 0.5f : 0.5f);
      return encode_png(bytes.data(), width, height, metadata, false);
    case ImageLayer::Kind::kDepth: {
      float lo = INFINITY, hi = -INFINITY;
      for (float d : layer.data)
        if (std::isfinite(d) && d < kBackgroundDepth) {
          lo = std::min(lo, d);
          hi = std::max(hi, d);
        }
      for (size_t i = 0; i < pixels; ++i) {
        const float d = layer.data[i];
        float v = 1.f;  // background: as far as can be
        if (std::isfinite(d) && d < kBackgroundDepth) v = hi > lo ? (d - lo) / (hi - lo) : 0.f;
        bytes[3 * i] = bytes[3 * i + 1] = bytes[3 * i + 2] = to_byte(v);
      }
      return encode_png(bytes.data(), width, height, metadata, false);
    }
  }
  throw ImageIoError("cannot encode image: unknown layer kind");
}

std::string layer_file_path(const std::string& path, const std::string& layer_name) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return path + "." + layer_name;
  return path.substr(0, dot) + "." + layer_name + path.substr(dot);
}

}  // namespace penumbra
