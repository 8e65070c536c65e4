#include "renderer/io/hdr_reader.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "renderer/core/row_blocks.h"
#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"

namespace penumbra {

// The decoder open_hdr returns (the header declares only that).
namespace {
class HdrImage final : public AssetDecoder {
 public:
  // open_hdr (hdr_reader.h).
  static std::unique_ptr<HdrImage> open(const ImageSource& source);
  ~HdrImage();
  HdrImage(const HdrImage&) = delete;
  HdrImage& operator=(const HdrImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // The first `channels` channels (R, G, B) as float, channel-interleaved, top row first.
  void read(int channels, float* pixels) override;
  // RGBE stores no 8-bit values: always throws ImageIoError.
  void read(int channels, uint8_t* pixels) override;

 private:
  struct State;
  explicit HdrImage(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
  PenumbraImageSpec spec_{};
};


constexpr size_t kMaxHeaderBytes = 64 * 1024;  // real headers are a few hundred bytes

// One line of the header without its newline; false at the end of the data or past the cap.
bool read_line(SourceReader& in, std::string* line, size_t* header_bytes) {
  line->clear();
  for (;;) {
    const int c = in.get();
    if (c < 0 || ++*header_bytes > kMaxHeaderBytes) return false;
    if (c == '\n') return true;
    line->push_back(char(c));
  }
}

// 2^(e - 136) for each shared exponent e (0: the pixel is black), the scale of RGBE's 8-bit
// mantissas: a component is mantissa x 2^(e - 136). A table: ldexp per component was 15% of
// loading an 8192 x 4096 map; every entry is a power of two, exact in float (2^-135 as a
// subnormal), so the values are ldexp's to the bit.
const std::array<float, 256> kExponentScale = [] {
  std::array<float, 256> t{};
  for (int e = 1; e < 256; ++e) t[size_t(e)] = std::ldexp(1.f, e - 136);
  return t;
}();

float rgbe_component(uint8_t mantissa, uint8_t exponent) {
  return float(mantissa) * kExponentScale[exponent];
}

}  // namespace

struct HdrImage::State {
  std::string path;
  std::unique_ptr<SourceReader> in;  // positioned at the first scanline
};

bool has_hdr_signature(const SourceHead& head) {
  return head.size >= 2 && head.bytes[0] == '#' && head.bytes[1] == '?';
}

HdrImage::HdrImage(std::unique_ptr<State> state) : state_(std::move(state)) {}
HdrImage::~HdrImage() = default;

std::unique_ptr<HdrImage> HdrImage::open(const ImageSource& source) {
  auto s = std::make_unique<State>();
  s->path = source.path;
  s->in = std::make_unique<SourceReader>(source);
  if (!s->in->ok()) throw ImageIoError(source.path + ": cannot open the file");
  auto fail = [&](const std::string& why) -> ImageIoError {
    return ImageIoError(source.path + ": cannot read the image: " + why);
  };
  std::string line;
  size_t header_bytes = 0;
  if (!read_line(*s->in, &line, &header_bytes) || line.rfind("#?", 0) != 0)
    throw fail("not a Radiance HDR file");
  for (;;) {  // variables up to an empty line
    if (!read_line(*s->in, &line, &header_bytes)) throw fail("the header is truncated or too long");
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0 && line != "FORMAT=32-bit_rle_rgbe") return nullptr;  // XYZE
  }
  if (!read_line(*s->in, &line, &header_bytes)) throw fail("no resolution line");
  long h = 0, w = 0;
  char tail = 0;
  if (std::sscanf(line.c_str(), "-Y %ld +X %ld%c", &h, &w, &tail) != 2) {
    // Another orientation (+Y, -X, transposed): valid, left to the plug-in.
    char a[3], b[3];
    if (std::sscanf(line.c_str(), "%2s %ld %2s %ld", a, &h, b, &w) == 4) return nullptr;
    throw fail("bad resolution line");
  }
  if (h <= 0 || w <= 0 || h > (1L << 30) || w > (1L << 30)) throw fail("bad resolution line");
  auto image = std::unique_ptr<HdrImage>(new HdrImage(std::move(s)));
  image->spec_ = PenumbraImageSpec{int(w), int(h), 1, 3, 1, 0};
  return image;
}

namespace {

// Reads one scanline of w pixels into `rgbe` (4 bytes a pixel, RGBE interleaved): run-length
// encoded or flat. `flat_file` carries from scanline to scanline: widths outside [8, 32767]
// cannot be run-length encoded, and a file whose first scanline is not is flat to its end
// (Radiance's reader reads it so; a flat pixel may look like an RLE mark). `component` is
// scratch of w bytes.
template <class Fail>
void read_scanline(SourceReader& in, size_t w, bool& flat_file, uint8_t* rgbe, uint8_t* component,
                   const Fail& fail) {
  uint8_t head[4];
  bool flat = flat_file;
  if (!flat) {
    if (!in.read(head, 4)) throw fail("the file ends early");
    flat = flat_file = !(head[0] == 2 && head[1] == 2 && (head[2] & 0x80) == 0);
    if (flat) {
      std::memcpy(rgbe, head, 4);  // the first pixel of a flat scanline
      if (!in.read(rgbe + 4, 4 * (w - 1))) throw fail("the file ends early");
    } else if ((size_t(head[2]) << 8 | head[3]) != w) {
      throw fail("a scanline's width differs from the image's");
    }
  } else if (!in.read(rgbe, 4 * w)) {
    throw fail("the file ends early");
  }
  if (flat) return;
  // Each of the four components in turn: runs (count > 128: one value count - 128 times) and
  // literals (count <= 128 values), never past the scanline's end.
  for (size_t c = 0; c < 4; ++c) {
    size_t x = 0;
    while (x < w) {
      const int count = in.get();
      if (count < 0) throw fail("the file ends early");
      if (count > 128) {
        const size_t n = size_t(count - 128);
        const int v = in.get();
        if (v < 0) throw fail("the file ends early");
        if (n > w - x) throw fail("a run overruns its scanline");
        std::memset(component + x, v, n);
        x += n;
      } else {
        const size_t n = size_t(count);
        if (n == 0 || n > w - x) throw fail("bad run length");
        if (!in.read(component + x, n)) throw fail("the file ends early");
        x += n;
      }
    }
    for (size_t i = 0; i < w; ++i) rgbe[4 * i + c] = component[i];
  }
}

// The first `channels` components of n RGBE pixels as floats.
void rgbe_to_float(const uint8_t* rgbe, size_t n, int channels, float* out) {
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < channels; ++c)
      out[i * size_t(channels) + size_t(c)] = rgbe_component(rgbe[4 * i + size_t(c)], rgbe[4 * i + 3]);
}

}  // namespace

// A pipeline over blocks of scanlines: the file is read and its runs decoded in order, one block
// after the other (scanlines have no index: each starts where the one before it ends), while
// the blocks already read are turned into floats on the other cores. A value's float is its
// RGBE bytes' alone, so the pixels are the same to the bit.
void HdrImage::read(int channels, float* pixels) {
  check_read_channels(spec_, channels, state_->path);
  const size_t w = size_t(spec_.width), h = size_t(spec_.height);
  SourceReader& in = *state_->in;
  auto fail = [&](const char* why) {
    return ImageIoError(state_->path + ": cannot decode the image: " + why);
  };
  struct Block {
    size_t begin = 0, end = 0;  // scanlines
    std::vector<uint8_t> rgbe;  // theirs, 4 bytes a pixel
  };
  using BlockPtr = std::shared_ptr<Block>;
  const size_t per_block = rows_per_block(w);
  std::vector<uint8_t> component(w);
  bool flat_file = w < 8 || w > 0x7fff;
  size_t next = 0;  // the first scanline not read yet
  // The pipeline's stages: the next block's scanlines read in file order (null after the last),
  // and a block's pixels turned into floats.
  const auto read_block = [&](tbb::flow_control& control) -> BlockPtr {
    if (next >= h) {
      control.stop();
      return nullptr;
    }
    auto b = std::make_shared<Block>();
    b->begin = next;
    b->end = next = std::min(h, next + per_block);
    b->rgbe.resize((b->end - b->begin) * 4 * w);
    for (size_t y = b->begin; y < b->end; ++y)
      read_scanline(in, w, flat_file, b->rgbe.data() + (y - b->begin) * 4 * w, component.data(), fail);
    return b;
  };
  const auto convert_block = [&](const BlockPtr& b) {
    rgbe_to_float(b->rgbe.data(), (b->end - b->begin) * w, channels, pixels + b->begin * w * size_t(channels));
  };
  // Isolated, as renderer/core/row_blocks.h's blocks (a caller may hold a lock); a few blocks in
  // flight per core (256 KB each for an 8192-wide map). An error thrown while reading ends the
  // pipeline and reaches the caller.
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_pipeline(size_t(2 * tbb::this_task_arena::max_concurrency()),
                           tbb::make_filter<void, BlockPtr>(tbb::filter_mode::serial_in_order, read_block) &
                               tbb::make_filter<BlockPtr, void>(tbb::filter_mode::parallel, convert_block));
  });
}

void HdrImage::read(int, uint8_t*) {
  throw ImageIoError(state_->path + ": the image does not store 8-bit values");
}

std::unique_ptr<AssetDecoder> open_hdr(const ImageSource& source) { return HdrImage::open(source); }

}  // namespace penumbra
