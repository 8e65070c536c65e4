#include "renderer/io/hdr_reader.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

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

void HdrImage::read(int channels, float* pixels) {
  check_read_channels(spec_, channels, state_->path);
  const size_t w = size_t(spec_.width);
  SourceReader& in = *state_->in;
  auto fail = [&](const char* why) {
    return ImageIoError(state_->path + ": cannot decode the image: " + why);
  };
  std::vector<uint8_t> row(4 * w);  // one scanline's pixels, RGBE interleaved
  std::vector<uint8_t> component(w);
  // Widths outside [8, 32767] cannot be run-length encoded; a file whose first scanline is not is
  // flat to its end (Radiance's reader reads it so; a flat pixel may look like an RLE mark).
  bool flat_file = w < 8 || w > 0x7fff;
  for (size_t y = 0; y < size_t(spec_.height); ++y) {
    uint8_t head[4];
    bool flat = flat_file;
    if (!flat) {
      if (!in.read(head, 4)) throw fail("the file ends early");
      flat = flat_file = !(head[0] == 2 && head[1] == 2 && (head[2] & 0x80) == 0);
      if (flat) {
        std::memcpy(row.data(), head, 4);  // the first pixel of a flat scanline
        if (!in.read(row.data() + 4, 4 * (w - 1))) throw fail("the file ends early");
      } else if ((size_t(head[2]) << 8 | head[3]) != w) {
        throw fail("a scanline's width differs from the image's");
      }
    } else if (!in.read(row.data(), 4 * w)) {
      throw fail("the file ends early");
    }
    if (!flat) {
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
            std::memset(component.data() + x, v, n);
            x += n;
          } else {
            const size_t n = size_t(count);
            if (n == 0 || n > w - x) throw fail("bad run length");
            if (!in.read(component.data() + x, n)) throw fail("the file ends early");
            x += n;
          }
        }
        for (size_t i = 0; i < w; ++i) row[4 * i + c] = component[i];
      }
    }
    float* out = pixels + y * w * size_t(channels);
    for (size_t i = 0; i < w; ++i)
      for (int c = 0; c < channels; ++c) out[i * size_t(channels) + size_t(c)] = rgbe_component(row[4 * i + size_t(c)], row[4 * i + 3]);
  }
}

void HdrImage::read(int, uint8_t*) {
  throw ImageIoError(state_->path + ": the image does not store 8-bit values");
}

std::unique_ptr<AssetDecoder> open_hdr(const ImageSource& source) { return HdrImage::open(source); }

}  // namespace penumbra
