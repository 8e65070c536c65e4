// penumbra merge PART.exr... -o OUT.{exr,png} [--layout plain|blender] [--denoise]
#include <cstdio>
#include <string>
#include <vector>

#include "api/version.h"
#include "app/commands.h"
#include "app/option_parsing.h"
#include "renderer/denoise/denoise_result.h"
#include "renderer/io/exr_window_file.h"
#include "renderer/io/image_io.h"
#include "renderer/io/layer_io.h"
#include "renderer/render/window_merge.h"

namespace penumbra::app {
namespace {

const char* kUsage =
    "usage: penumbra merge PART.exr... -o OUT.{exr,png} [options]\n"
    "\n"
    "Joins the windows of one frame, rendered apart with penumbra render --window, into the\n"
    "whole frame. Every pixel must be in exactly one part (overlaps and holes are errors), and\n"
    "every part must carry the same output layers. Pixels are copied as rendered: with uniform\n"
    "sampling the result equals the render of the whole frame bit for bit\n"
    "(docs/animation-and-windows.md).\n"
    "  -o, --output FILE        the frame; .exr (linear float) or .png (sRGB 8-bit)\n"
    "  --layout NAME            plain or blender (.exr, as penumbra render); default: the parts'\n"
    "  --denoise                denoise the merged frame with Open Image Denoise, guided by the\n"
    "                           parts' albedo and normal layers when present (a window cannot be\n"
    "                           denoised alone: the denoiser looks across window edges)\n";

// Header attributes that describe one part, not the frame.
bool per_part_attribute(const std::string& name) {
  return name == "penumbra:render_seconds" || name == "penumbra:spp_mean";
}

}  // namespace

int run_merge(int argc, char** argv) {
  std::vector<std::string> inputs;
  std::string output, layout_name;
  bool denoise = false;
  OptionParser p(argc, argv);
  while (p.next()) {
    if (p.is("-h") || p.is("--help")) {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (p.is("-o") || p.is("--output")) {
      if (!p.value(&output)) return p.fail(kUsage);
    } else if (p.is("--layout")) {
      if (!p.value(&layout_name)) return p.fail(kUsage);
    } else if (p.is("--denoise")) {
      std::string v;
      p.switch_value(&v);
      if (v != "true" && v != "false") return p.fail(kUsage, "--denoise takes true or false");
      denoise = v == "true";
    } else if (p.positional()) {
      inputs.push_back(p.arg());
    } else {
      return p.fail(kUsage, "unknown option " + std::string(p.arg()));
    }
  }
  if (inputs.empty()) return p.fail(kUsage, "no parts given");
  if (output.empty()) return p.fail(kUsage, "no output given (-o)");
  if (!layout_name.empty() && layout_name != "plain" && layout_name != "blender")
    return p.fail(kUsage, "unknown --layout " + layout_name + " (plain or blender)");
  try {
    const ImageFormat format = image_format_from_path(output);
    std::vector<WindowPart> parts;
    PixelWindow display;
    ExrLayout layout = ExrLayout::kPlain;
    ImageMetadata meta;
    for (const std::string& path : inputs) {
      ExrWindowFile file = read_exr_window(path);
      if (parts.empty()) {
        display = file.display;
        layout = file.layout;
        for (auto& [k, v] : file.metadata)
          if (!per_part_attribute(k) && k != "BlenderMultiChannel") meta.emplace_back(k, v);
      } else if (!(file.display == display)) {
        std::fprintf(stderr, "penumbra merge: %s: the frame is %dx%d, %s's is %dx%d: parts of different frames\n",
                     path.c_str(), file.display.width(), file.display.height(), inputs.front().c_str(),
                     display.width(), display.height());
        return 1;
      }
      parts.push_back(std::move(file.part));
    }
    if (layout_name == "plain") layout = ExrLayout::kPlain;
    if (layout_name == "blender") layout = ExrLayout::kBlender;
    MergedImage merged = merge_windows(parts, display.width(), display.height());
    parts.clear();
    meta.emplace_back("penumbra:merged_parts", std::to_string(inputs.size()));

    RenderResult result;
    result.image = std::move(merged.image);
    result.layers = std::move(merged.layers);
    if (denoise) {
      uint32_t present = 0;
      for (const ImageLayer& l : result.layers)
        for (int i = 0; i < kOutputLayerCount; ++i)
          if (l.name == kOutputLayerNames[i]) present |= 1u << i;
      denoise_result(present, &result);
      meta.push_back({"penumbra:denoised", result.stats.denoised ? "true" : "false"});
      if (!result.stats.denoised)
        std::fprintf(stderr, "penumbra merge: warning: the image is not denoised: %s\n",
                     result.stats.denoise_error.c_str());
    }
    if (format == ImageFormat::kPng) {
      write_image_file(output, result.image, meta);
      for (const ImageLayer& layer : result.layers)
        write_file_atomically(layer_file_path(output, layer.name),
                              encode_layer(layer, result.image.width, result.image.height, format, meta));
    } else {
      write_file_atomically(output, encode_layered_exr(result.image, result.layers, layout, meta));
    }
    std::fprintf(stderr, "merged %zu parts -> %s: %dx%d%s\n", inputs.size(), output.c_str(),
                 result.image.width, result.image.height, result.stats.denoised ? ", denoised" : "");
  } catch (const WindowMergeError& e) {
    std::fprintf(stderr, "penumbra merge: %s\n", e.what());
    return 1;
  } catch (const ImageIoError& e) {
    std::fprintf(stderr, "penumbra merge: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace penumbra::app
