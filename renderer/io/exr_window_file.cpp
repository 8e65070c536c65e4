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

// The size of OpenEXR's fixed-layout attribute types (ImfStandardAttributes, ImfAttribute.cpp's
// type list); -1 for variable-length ones (string, chlist, stringvector, preview, opaque).
int fixed_attribute_size(const std::string& type) {
  static const std::pair<const char*, int> kSizes[] = {
      {"int", 4},      {"float", 4},     {"double", 8},      {"v2i", 8},         {"v2f", 8},
      {"v2d", 16},     {"v3i", 12},      {"v3f", 12},        {"v3d", 24},        {"box2i", 16},
      {"box2f", 16},   {"m33f", 36},     {"m33d", 72},       {"m44f", 64},       {"m44d", 128},
      {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"chromaticities", 32}, {"rational", 8}, {"timecode", 8}, {"keycode", 28}, {"tiledesc", 9}};
  for (const auto& [name, size] : kSizes)
    if (type == name) return size;
  return -1;
}

// OpenEXR 3.1 allocates an attribute's value at the size the file declares before reading it, so
// a 40-byte file can make it allocate 2 GB (found by the exr_window fuzzer). Walk the header
// first (OpenEXR file layout: magic, version, then name\0 type\0 int32 size value, up to a
// null byte) and refuse any size beyond the bytes the file holds. `head` is the file's start,
// at most kMaxHeaderBytes; `file_size` the whole file's.
constexpr size_t kMaxHeaderBytes = size_t(1) << 20;

uint32_t le32(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

void check_header(const uint8_t* head, size_t head_size, uint64_t file_size, const std::string& path) {
  if (head_size < 8 || le32(head) != 20000630u) throw ImageIoError(path + ": not an OpenEXR file");
  // Multi-part (0x1000) and deep (0x800) files are nothing penumbra writes for a window.
  if (le32(head + 4) & 0x1800u) throw ImageIoError(path + ": a multi-part or deep EXR, not a window of a frame");
  size_t pos = 8;
  auto skip_text = [&](const char* what) {
    const size_t end = std::min(head_size, pos + 256);
    const uint8_t* zero = static_cast<const uint8_t*>(std::memchr(head + pos, 0, end - pos));
    if (!zero) throw ImageIoError(path + ": the header's attribute " + what + " is unterminated or too long");
    pos = size_t(zero - head) + 1;
  };
  while (true) {
    if (pos >= head_size)
      throw ImageIoError(path + ": the header is truncated or larger than " + std::to_string(kMaxHeaderBytes) + " bytes");
    if (head[pos] == 0) return;
    const size_t name_at = pos;
    skip_text("name");
    const std::string name(reinterpret_cast<const char*>(head + name_at));
    skip_text("type");
    if (pos + 4 > head_size) throw ImageIoError(path + ": the header is truncated");
    const int32_t size = int32_t(le32(head + pos));
    pos += 4;
    if (size < 0 || uint64_t(size) > file_size - pos)
      throw ImageIoError(path + ": header attribute \"" + name + "\" claims " + std::to_string(size) +
                         " bytes, more than the file holds");
    // OpenEXR reads typed values by their own layout, not by the declared size: the two must
    // agree, or its reading and this walk part ways and a later size goes unchecked.
    const std::string type(reinterpret_cast<const char*>(head + name_at + name.size() + 1));
    const uint8_t* value = head + pos;
    const size_t available = std::min<size_t>(size_t(size), head_size - std::min(head_size, pos));
    auto bad = [&](const char* why) {
      return ImageIoError(path + ": header attribute \"" + name + "\" (" + type + "): " + why);
    };
    if (const int fixed = fixed_attribute_size(type); fixed >= 0) {
      if (size != fixed) throw bad("wrong size");
    } else if (type == "chlist") {
      // Entries "name\0" + 16 bytes, then a null byte ending exactly at the declared size.
      size_t at = 0;
      while (at < available && value[at] != 0) {
        const uint8_t* zero = static_cast<const uint8_t*>(std::memchr(value + at, 0, available - at));
        if (!zero) throw bad("unterminated channel name");
        at = size_t(zero - value) + 1 + 16;
      }
      if (at + 1 != size_t(size) || at >= available) throw bad("channel list does not fill its size");
    } else if (type == "stringvector") {
      size_t at = 0;
      while (at < size_t(size)) {
        if (at + 4 > available) throw bad("truncated");
        const int32_t n = int32_t(le32(value + at));
        if (n < 0 || size_t(n) > size_t(size) - at - 4) throw bad("a string beyond the attribute");
        at += 4 + size_t(n);
      }
    } else if (type == "preview") {
      if (available < 8 || size_t(size) != 8 + 4 * uint64_t(le32(value)) * le32(value + 4)) throw bad("wrong size");
    }
    pos += size_t(size);
  }
}

// Encoded bytes held in memory as an OpenEXR input stream.
class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(const std::string& name, const std::vector<uint8_t>& bytes)
      : Imf::IStream(name.c_str()), bytes_(bytes) {}
  bool read(char c[], int n) override {
    // pos_ comes from seekg, i.e. from offsets in the file: compare without overflowing.
    if (n < 0 || pos_ > bytes_.size() || uint64_t(n) > bytes_.size() - pos_)
      throw std::runtime_error("unexpected end of file");
    std::memcpy(c, bytes_.data() + pos_, size_t(n));
    pos_ += uint64_t(n);
    return pos_ < bytes_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }

 private:
  const std::vector<uint8_t>& bytes_;
  uint64_t pos_ = 0;
};

ExrWindowFile read_stream(Imf::IStream& stream, const std::string& path, const ExrWindowLimits& limits) {
  ExrWindowFile out;
  out.part.name = path;
  try {
    Imf::InputFile file(stream, 1);
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
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImageIoError(path + ": cannot open the file");
    in.seekg(0, std::ios::end);
    const uint64_t file_size = uint64_t(std::max<std::streamoff>(0, in.tellg()));
    in.seekg(0);
    std::vector<uint8_t> head(size_t(std::min<uint64_t>(file_size, kMaxHeaderBytes)));
    in.read(reinterpret_cast<char*>(head.data()), std::streamsize(head.size()));
    if (!in) throw ImageIoError(path + ": cannot read the file");
    check_header(head.data(), head.size(), file_size, path);
  }
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
  check_header(bytes.data(), std::min(bytes.size(), kMaxHeaderBytes), bytes.size(), name);
  MemoryIStream stream(name, bytes);
  return read_stream(stream, name, limits);
}

}  // namespace penumbra
