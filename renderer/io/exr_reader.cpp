#include "renderer/io/exr_reader.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStdIO.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include "renderer/io/exr_header_check.h"
#include "renderer/io/exr_threads.h"
#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"

namespace penumbra {

// The decoder open_exr returns (the header declares only that).
namespace {
class ExrImage final : public AssetDecoder {
 public:
  // open_exr (exr_reader.h).
  static std::unique_ptr<ExrImage> open(const ImageSource& source);
  ~ExrImage();
  ExrImage(const ExrImage&) = delete;
  ExrImage& operator=(const ExrImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // The first `channels` channels as float, channel-interleaved, top row first.
  void read(int channels, float* pixels) override;
  // EXR stores no 8-bit values: always throws ImageIoError.
  void read(int channels, uint8_t* pixels) override;

 private:
  struct State;
  explicit ExrImage(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
  PenumbraImageSpec spec_{};
};


// The channel sets this reader takes, in the order OpenImageIO gives them.
constexpr std::array<std::array<const char*, 4>, 4> kLayouts = {{
    {"R", "G", "B", "A"}, {"R", "G", "B", nullptr}, {"Y", "A", nullptr, nullptr}, {"Y", nullptr, nullptr, nullptr}}};

// The layout whose names are exactly the file's channels (half or float, unsubsampled), or -1.
int layout_of(const Imf::ChannelList& list) {
  std::vector<std::string> names;
  for (auto it = list.begin(); it != list.end(); ++it) {
    const Imf::Channel& c = it.channel();
    if (c.type == Imf::UINT || c.xSampling != 1 || c.ySampling != 1) return -1;
    names.emplace_back(it.name());
    if (names.size() > 4) return -1;
  }
  for (size_t k = 0; k < kLayouts.size(); ++k) {
    size_t n = 0;
    while (n < 4 && kLayouts[k][n]) ++n;
    if (n != names.size()) continue;
    bool all = true;
    for (size_t i = 0; i < n; ++i) all &= std::find(names.begin(), names.end(), kLayouts[k][i]) != names.end();
    if (all) return int(k);
  }
  return -1;
}

// OpenEXR checks the windows against these before it sizes anything by them (tile offset tables
// of a tiled file's header): far above penumbra's own limits (ImageReadLimits), which are checked
// after the header is read, far below what a hostile header can claim.
void limit_openexr_sizes() {
  static std::once_flag once;
  std::call_once(once, [] {
    Imf::Header::setMaxImageSize(1 << 17, 1 << 17);
    Imf::Header::setMaxTileSize(1 << 17, 1 << 17);
  });
}

}  // namespace

struct ExrImage::State {
  std::string path;
  std::shared_ptr<const std::vector<uint8_t>> bytes;  // an image in memory: kept alive
  std::unique_ptr<Imf::IStream> stream;
  std::unique_ptr<Imf::InputFile> file;
  int layout = -1;
};

bool has_exr_signature(const SourceHead& head) {
  const uint8_t* b = head.bytes;
  return head.size >= 4 && b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01;
}

ExrImage::ExrImage(std::unique_ptr<State> state) : state_(std::move(state)) {}
ExrImage::~ExrImage() = default;

std::unique_ptr<ExrImage> ExrImage::open(const ImageSource& source) {
  limit_openexr_sizes();
  const std::string& path = source.path;
  const uint32_t flags =
      source.bytes ? check_exr_header(source.bytes->data(), std::min(source.bytes->size(), kMaxExrHeaderBytes),
                                      source.bytes->size(), path)
                   : check_exr_file_header(path);
  if (flags & (kExrMultiPart | kExrDeep)) return nullptr;
  auto s = std::make_unique<State>();
  s->path = path;
  try {
    if (source.bytes) {
      s->bytes = source.bytes;
      s->stream = std::make_unique<ExrMemoryStream>(path, *s->bytes);
    } else {
      s->stream = std::make_unique<Imf::StdIFStream>(path.c_str());
    }
    s->file = std::make_unique<Imf::InputFile>(*s->stream, exr_threads());
  } catch (const std::exception& e) {
    throw ImageIoError(path + ": cannot read the image: " + e.what());
  }
  const Imf::Header& header = s->file->header();
  s->layout = layout_of(header.channels());
  if (s->layout < 0) return nullptr;
  const Imath::Box2i dw = header.dataWindow();
  const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > (1 << 30) || h > (1 << 30))
    throw ImageIoError(path + ": cannot read the image: the data window is empty or out of range");
  auto image = std::unique_ptr<ExrImage>(new ExrImage(std::move(s)));
  PenumbraImageSpec& spec = image->spec_;
  spec.width = int(w);
  spec.height = int(h);
  spec.depth = 1;
  int n = 0;
  while (n < 4 && kLayouts[size_t(image->state_->layout)][size_t(n)]) ++n;
  spec.channels = n;
  spec.is_float = 1;
  spec.is_uint8 = 0;
  return image;
}

void ExrImage::read(int channels, float* pixels) {
  check_read_channels(spec_, channels, state_->path);
  try {
    Imf::InputFile& file = *state_->file;
    const Imath::Box2i dw = file.header().dataWindow();
    const size_t stride = size_t(channels) * sizeof(float);
    Imf::FrameBuffer frame;
    for (int c = 0; c < channels; ++c)
      frame.insert(kLayouts[size_t(state_->layout)][size_t(c)],
                   Imf::Slice::Make(Imf::FLOAT, pixels + c, dw, stride, stride * size_t(spec_.width)));
    file.setFrameBuffer(frame);
    file.readPixels(dw.min.y, dw.max.y);
  } catch (const std::exception& e) {
    throw ImageIoError(state_->path + ": cannot decode the image: " + e.what());
  }
}

void ExrImage::read(int, uint8_t*) {
  throw ImageIoError(state_->path + ": the image does not store 8-bit values");
}

std::unique_ptr<AssetDecoder> open_exr(const ImageSource& source) { return ExrImage::open(source); }

}  // namespace penumbra
