#pragma once
// Encoding of the output layers (albedo, normal, depth; renderer/render/output_layers.h) beside
// the beauty image: one multi-layer EXR, or one file per layer (docs/output-layers.md).
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/pixel_window.h"
#include "renderer/io/image_io.h"

namespace penumbra {

// How the channels of a multi-layer EXR are named.
//  * kPlain: the beauty as R, G, B (what any EXR reader shows), each layer as "<layer>.<ch>":
//    albedo.R/G/B, normal.X/Y/Z, depth.Z.
//  * kBlender: Blender's render-result layout (one view layer "ViewLayer", passes named as
//    Blender names them): ViewLayer.Combined.R/G/B/A (A = 1), ViewLayer.Denoising Albedo.R/G/B,
//    ViewLayer.Normal.X/Y/Z, ViewLayer.Depth.Z, and the "BlenderMultiChannel" header attribute
//    Blender's own multi-layer files carry; RenderResult.load_from_file reads it.
enum class ExrLayout { kPlain, kBlender };

// Channel names of one layer in a layout (with its layer prefix), in data order.
std::vector<std::string> exr_channel_names(const ImageLayer& layer, ExrLayout layout);

// Beauty and layers in one EXR. Non-finite values are written as 0. Throws ImageIoError.
// With `data_window` and `display_window` (both or neither), the images are that data window
// of that display window (encode_exr_channels).
std::vector<uint8_t> encode_layered_exr(const Image& beauty, const std::vector<ImageLayer>& layers,
                                        ExrLayout layout, const ImageMetadata& metadata = {},
                                        const PixelWindow* data_window = nullptr,
                                        const PixelWindow* display_window = nullptr);

// One layer as its own image. EXR: linear float, the layer's plain channel names without
// prefix (R, G, B; X, Y, Z; Z). PNG, 8 bits: albedo sRGB-encoded like the beauty image; normal
// as n * 0.5 + 0.5 per channel, clamped, written as data (no sRGB chunk); depth as grey,
// (d - near) / (far - near) over the pixels that saw a surface (near black, far white), the
// background white, also as data. Throws ImageIoError.
std::vector<uint8_t> encode_layer(const ImageLayer& layer, int width, int height,
                                  ImageFormat format, const ImageMetadata& metadata = {},
                                  const PixelWindow* data_window = nullptr,
                                  const PixelWindow* display_window = nullptr);

// The file a layer goes to beside the beauty image's: "out.png" -> "out.albedo.png"
// (the layer's name before the extension; appended when there is no extension).
std::string layer_file_path(const std::string& path, const std::string& layer_name);

}  // namespace penumbra
