#include "renderer/io/exr_writer.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cstring>
#include <exception>

#include "renderer/io/exr_threads.h"
#include "renderer/io/image_io.h"

namespace penumbra {
namespace {

// An Imf::OStream into memory. A scan-line file seeks back to fill in its line offset table, so
// writes go to the current position, which may be before the end.
class MemoryStream : public Imf::OStream {
 public:
  MemoryStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    const size_t end = pos_ + size_t(n);
    if (end > bytes_.size()) bytes_.resize(end);
    std::memcpy(bytes_.data() + pos_, c, size_t(n));
    pos_ = end;
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = size_t(pos); }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
  size_t pos_ = 0;
};

}  // namespace

std::vector<uint8_t> encode_exr_channels(const std::vector<ExrChannel>& channels, int width,
                                         int height, const ImageMetadata& metadata,
                                         const PixelWindow* data, const PixelWindow* display) {
  try {
    if (data && (data->width() != width || data->height() != height))
      throw ImageIoError("cannot encode image: the data window is not the image's size");
    const PixelWindow whole{0, 0, width, height};
    const PixelWindow& dw = data && display ? *data : whole;
    const PixelWindow& full = data && display ? *display : whole;
    // OpenEXR windows are inclusive pixel ranges.
    Imf::Header header(Imath::Box2i({full.x0, full.y0}, {full.x1 - 1, full.y1 - 1}),
                       Imath::Box2i({dw.x0, dw.y0}, {dw.x1 - 1, dw.y1 - 1}));
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const ExrChannel& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
    for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
    Imf::FrameBuffer frame;
    for (const ExrChannel& c : channels) {
      // OpenEXR addresses a slice by absolute pixel coordinates: the base is where pixel (0, 0)
      // would be (its documented convention for data windows not at the origin).
      char* base = reinterpret_cast<char*>(const_cast<float*>(c.base)) -
                   (std::ptrdiff_t(dw.x0) + std::ptrdiff_t(dw.y0) * width) * std::ptrdiff_t(c.x_stride);
      frame.insert(c.name, Imf::Slice(Imf::FLOAT, base, c.x_stride, c.x_stride * size_t(width)));
    }
    MemoryStream stream;
    {
      Imf::OutputFile file(stream, header, exr_threads());
      file.setFrameBuffer(frame);
      file.writePixels(height);
    }
    return stream.take();
  } catch (const ImageIoError&) {
    throw;
  } catch (const std::exception& e) {
    throw ImageIoError(std::string("cannot encode image: ") + e.what());
  }
}

std::vector<uint8_t> encode_exr(const float* rgb, int width, int height,
                                const ImageMetadata& metadata) {
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* name : {"R", "G", "B"}) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
    const size_t x_stride = 3 * sizeof(float), y_stride = x_stride * size_t(width);
    Imf::FrameBuffer frame;
    char* base = reinterpret_cast<char*>(const_cast<float*>(rgb));
    frame.insert("R", Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
    frame.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), x_stride, y_stride));
    frame.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), x_stride, y_stride));
    MemoryStream stream;
    {
      // The chunks compressed on OpenEXR's pool (exr_threads.h): the same bytes.
      Imf::OutputFile file(stream, header, exr_threads());
      file.setFrameBuffer(frame);
      file.writePixels(height);
    }  // the destructor writes the line offset table
    return stream.take();
  } catch (const std::exception& e) {
    throw ImageIoError(std::string("cannot encode image: ") + e.what());
  }
}

}  // namespace penumbra
