#include "renderer/io/exr_window_file.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <vector>

#include "renderer/io/exr_header_check.h"
#include "renderer/io/exr_threads.h"
#include "renderer/io/image_io.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {
namespace {

// The layers a render can write beside the beauty image, with the kinds output_layers.h gives
// them (layer_io.cpp names their channels from the kind).
std::vector<ImageLayer> known_layers() {
  return {{kOutputLayerNames[0], ImageLayer::Kind::kColor, 3, {}},
          {kOutputLayerNames[1], ImageLayer::Kind::kVector, 3, {}},
          {kOutputLayerNames[2], ImageLayer::Kind::kDepth, 1, {}}};
}

// Multi-part (0x1000) and deep (0x800) files are nothing penumbra writes for a window.
void refuse_multi_part_or_deep(uint32_t flags, const std::string& path) {
  if (flags & (kExrMultiPart | kExrDeep))
    throw ImageIoError(path + ": a multi-part or deep EXR, not a window of a frame");
}

ExrWindowFile read_stream(Imf::IStream& stream, const std::string& path, const ExrWindowLimits& limits) {
  ExrWindowFile out;
  out.part.name = path;
  try {
    Imf::InputFile file(stream, exr_threads());
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow(), disp = header.displayWindow();
    // Exclusive ends below must not overflow; anything near INT_MAX is far over the limits anyway.
    constexpr int kMaxCoordinate = 1 << 30;
    for (int v : {dw.min.x, dw.min.y, dw.max.x, dw.max.y, disp.max.x, disp.max.y})
      if (v < -kMaxCoordinate || v > kMaxCoordinate)
        throw ImageIoError(path + ": a data or display window coordinate is out of range");
    if (disp.min.x != 0 || disp.min.y != 0)
      throw ImageIoError(path + ": the display window does not start at pixel (0, 0)");
    out.display = {0, 0, disp.max.x + 1, disp.max.y + 1};
    out.part.window = {dw.min.x, dw.min.y, dw.max.x + 1, dw.max.y + 1};
    if (out.display.empty() || out.display.pixel_count() > limits.max_pixels)
      throw ImageIoError(path + ": the display window of " + std::to_string(out.display.width()) + "x" +
                         std::to_string(out.display.height()) + " pixels is empty or over the limit of " +
                         std::to_string(limits.max_pixels) + " pixels");
    if (!out.part.window.fits(out.display.width(), out.display.height()))
      throw ImageIoError(path + ": the data window is not inside the display window");

    const Imf::ChannelList& list = header.channels();
    int count = 0;
    bool has_plain = false, has_blender = false;
    for (auto it = list.begin(); it != list.end(); ++it) {
      if (++count > limits.max_channels)
        throw ImageIoError(path + ": more than " + std::to_string(limits.max_channels) + " channels");
      has_plain |= std::string(it.name()) == "R";
      has_blender |= std::string(it.name()) == "ViewLayer.Combined.R";
    }
    if (!has_plain && !has_blender)
      throw ImageIoError(path + ": no beauty image (channels R, G, B or ViewLayer.Combined.R, G, B)");
    out.layout = has_plain ? ExrLayout::kPlain : ExrLayout::kBlender;

    const int w = out.part.window.width(), h = out.part.window.height();
    const size_t pixels = size_t(out.part.window.pixel_count());
    out.part.image = Image(w, h);
    std::vector<ImageLayer> layers;
    for (ImageLayer& l : known_layers()) {
      bool all = true, any = false;
      for (const std::string& name : exr_channel_names(l, out.layout)) {
        const bool present = list.findChannel(name) != nullptr;
        all &= present;
        any |= present;
      }
      if (any && !all) throw ImageIoError(path + ": layer " + l.name + " lacks some of its channels");
      if (!all) continue;
      l.data.assign(pixels * size_t(l.channels), 0.f);
      layers.push_back(std::move(l));
    }

    // Slices are addressed by absolute pixel coordinates (see exr_writer.cpp); every channel is
    // converted to float on reading, whatever its stored type.
    const std::ptrdiff_t origin = std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * w;
    Imf::FrameBuffer frame;
    const std::string prefix = out.layout == ExrLayout::kBlender ? "ViewLayer.Combined." : "";
    for (int c = 0; c < 3; ++c) {
      const std::string name = prefix + "RGB"[c];
      if (!list.findChannel(name)) throw ImageIoError(path + ": no channel " + name);
      char* base = reinterpret_cast<char*>(out.part.image.rgb.data() + c) -
                   origin * std::ptrdiff_t(3 * sizeof(float));
      frame.insert(name, Imf::Slice(Imf::FLOAT, base, 3 * sizeof(float), 3 * sizeof(float) * size_t(w)));
    }
    for (ImageLayer& l : layers) {
      const std::vector<std::string> names = exr_channel_names(l, out.layout);
      const size_t stride = size_t(l.channels) * sizeof(float);
      for (int c = 0; c < l.channels; ++c) {
        char* base = reinterpret_cast<char*>(l.data.data() + c) - origin * std::ptrdiff_t(stride);
        frame.insert(names[size_t(c)], Imf::Slice(Imf::FLOAT, base, stride, stride * size_t(w)));
      }
    }
    file.setFrameBuffer(frame);
    file.readPixels(dw.min.y, dw.max.y);
    for (auto it = header.begin(); it != header.end(); ++it)
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        out.metadata.emplace_back(it.name(), s->value());
    // A part is merged as it is; a non-finite value would end up in the frame (an image never
    // holds one), so it is refused here with the file named.
    auto finite = [&](const std::vector<float>& v, const std::string& what) {
      for (float f : v)
        if (!std::isfinite(f)) throw ImageIoError(path + ": " + what + " holds a non-finite value");
    };
    finite(out.part.image.rgb, "the image");
    for (const ImageLayer& l : layers) finite(l.data, "layer " + l.name);
    out.part.layers = std::move(layers);
  } catch (const ImageIoError&) {
    throw;
  } catch (const std::exception& e) {
    throw ImageIoError(path + ": " + e.what());
  }
  return out;
}

}  // namespace

ExrWindowFile read_exr_window(const std::string& path, const ExrWindowLimits& limits) {
  refuse_multi_part_or_deep(check_exr_file_header(path), path);
  std::unique_ptr<Imf::IStream> stream;
  try {
    stream = std::make_unique<Imf::StdIFStream>(path.c_str());
  } catch (const std::exception& e) {
    throw ImageIoError(path + ": " + e.what());
  }
  return read_stream(*stream, path, limits);
}

ExrWindowFile read_exr_window(const std::string& name, const std::vector<uint8_t>& bytes,
                              const ExrWindowLimits& limits) {
  refuse_multi_part_or_deep(
      check_exr_header(bytes.data(), std::min(bytes.size(), kMaxExrHeaderBytes), bytes.size(), name), name);
  ExrMemoryStream stream(name, bytes);
  return read_stream(stream, name, limits);
}

}  // namespace penumbra
