#include "renderer/io/png_reader.h"

#include <png.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"

namespace penumbra {

// The decoder open_png returns (the header declares only that).
namespace {
class PngImage final : public AssetDecoder {
 public:
  // open_png (png_reader.h).
  static std::unique_ptr<PngImage> open(const ImageSource& source);
  ~PngImage();
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // The first `channels` channels (at most spec().channels), channel-interleaved, top row first:
  // as float in [0, 1] (value / 255 or / 65535), or as the stored 8-bit values (8-bit images only).
  void read(int channels, float* pixels) override;
  void read(int channels, uint8_t* pixels) override;

 private:
  struct State;
  explicit PngImage(std::unique_ptr<State> state);
  std::vector<uint8_t> decode();  // every row at the stored depth, after the expansions above
  std::unique_ptr<State> state_;
  PenumbraImageSpec spec_{};
};


constexpr size_t kSignatureBytes = 8;

// What libpng's callbacks reach through their pointers: the bytes' source and the last error.
struct PngIo {
  explicit PngIo(const ImageSource& source) : in(source) {}
  SourceReader in;
  char error[256] = "";
};

// libpng's contract: an error handler must not return; it longjmps to the setjmp point of the
// call that failed (below), after the message is kept for the exception thrown there. Nothing is
// printed: hostile files must not write to the service's log through stderr.
[[noreturn]] void on_error(png_structp png, png_const_charp message) {
  auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
  std::snprintf(io->error, sizeof io->error, "%s", message ? message : "libpng failed");
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

void read_bytes(png_structp png, png_bytep out, size_t n) {
  if (!static_cast<PngIo*>(png_get_io_ptr(png))->in.read(out, n)) png_error(png, "the data ends early");
}

// The libpng calls that may fail, each behind its own setjmp point: these frames hold nothing
// with a destructor and change no local after setjmp, so an error's longjmp is well defined.
bool read_info(png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int type = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  // OpenImageIO's PNG reader's expansions, so both give the same channels and values.
  if (type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  if (depth == 16) png_set_swap(png);  // PNG stores 16-bit values big-endian
#endif
  png_set_interlace_handling(png);
  return true;
}

// libpng allocates (and clears) its row buffers at png_read_update_info, by the width the header
// claims: it runs here, after the caller has checked the size against its limits, not when the
// header is read (a header claiming 2^31 pixels per row would make that 16 GB).
bool read_rows(png_structp png, png_infop info, png_bytepp rows, size_t expected_row_bytes) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != expected_row_bytes) png_error(png, "unexpected row size");
  png_read_image(png, rows);
  return true;
}

}  // namespace

struct PngImage::State {
  explicit State(const ImageSource& source) : path(source.path), io(source) {}
  std::string path;
  PngIo io;
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~State() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw ImageIoError(path + ": " + what + ": " + io.error);
  }
};

bool has_png_signature(const SourceHead& head) {
  return head.size == kSignatureBytes && png_sig_cmp(head.bytes, 0, kSignatureBytes) == 0;
}

PngImage::PngImage(std::unique_ptr<State> state) : state_(std::move(state)) {}
PngImage::~PngImage() = default;

std::unique_ptr<PngImage> PngImage::open(const ImageSource& source) {
  auto s = std::make_unique<State>(source);
  if (!s->io.in.ok()) throw ImageIoError(source.path + ": cannot open the file");
  s->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s->io, on_error, on_warning);
  if (s->png) s->info = png_create_info_struct(s->png);
  if (!s->png || !s->info) throw ImageIoError(source.path + ": cannot read the image: libpng could not start");
  png_set_read_fn(s->png, &s->io, read_bytes);
  // Sizes are checked by the caller against its limits (image_reader.cpp) before any row is
  // allocated, with its own messages; libpng's default limit (a million per side) would answer
  // first for some of them.
  png_set_user_limits(s->png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  // Only IHDR, PLTE, tRNS, IDAT and IEND are read; every other chunk (text, ICC profiles, EXIF)
  // is skipped unread. libpng's check of a chunk's declared length is a benign error, a warning
  // on reading, after which it would allocate that length (2 GB for a 400-byte file, found by
  // the image_asset fuzzer); skipped chunks are read through a small buffer instead.
  png_set_keep_unknown_chunks(s->png, PNG_HANDLE_CHUNK_NEVER, nullptr, -1);
  png_set_chunk_malloc_max(s->png, 8u << 20);
  if (!read_info(s->png, s->info)) s->fail("cannot read the image");

  auto image = std::unique_ptr<PngImage>(new PngImage(std::move(s)));
  png_structp png = image->state_->png;
  png_infop info = image->state_->info;
  PenumbraImageSpec& spec = image->spec_;
  spec.width = int(png_get_image_width(png, info));
  spec.height = int(png_get_image_height(png, info));
  spec.depth = 1;
  // The channels after read_info's expansions (libpng reports them only after
  // png_read_update_info, which decode() calls): palettes become RGB, a tRNS chunk adds alpha.
  const int type = png_get_color_type(png, info);
  spec.channels = type == PNG_COLOR_TYPE_GRAY ? 1 : type == PNG_COLOR_TYPE_GRAY_ALPHA ? 2
                  : type == PNG_COLOR_TYPE_RGB_ALPHA ? 4 : 3;
  if (png_get_valid(png, info, PNG_INFO_tRNS) && (type & PNG_COLOR_MASK_ALPHA) == 0) ++spec.channels;
  spec.is_float = 0;
  spec.is_uint8 = png_get_bit_depth(png, info) == 16 ? 0 : 1;
  return image;
}

std::vector<uint8_t> PngImage::decode() {
  const size_t row_bytes = size_t(spec_.width) * size_t(spec_.channels) * (spec_.is_uint8 ? 1 : 2);
  std::vector<uint8_t> data(row_bytes * size_t(spec_.height));
  std::vector<png_bytep> rows(size_t(spec_.height));
  for (size_t y = 0; y < rows.size(); ++y) rows[y] = data.data() + y * row_bytes;
  if (!read_rows(state_->png, state_->info, rows.data(), row_bytes)) state_->fail("cannot decode the image");
  return data;
}

void PngImage::read(int channels, float* pixels) {
  check_read_channels(spec_, channels, state_->path);
  const std::vector<uint8_t> data = decode();
  const size_t n = size_t(spec_.width) * size_t(spec_.height);
  if (spec_.is_uint8) return widen_8bit(data.data(), n, spec_.channels, channels, pixels);
  // 16 bits: value times 1/65535 in float, OpenImageIO's conversion, as widen_8bit's.
  const float scale = 1.f / 65535.f;
  const size_t in_channels = size_t(spec_.channels);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < channels; ++c) {
      uint16_t v;
      std::memcpy(&v, data.data() + 2 * (i * in_channels + size_t(c)), sizeof v);
      pixels[i * size_t(channels) + size_t(c)] = float(v) * scale;
    }
}

void PngImage::read(int channels, uint8_t* pixels) {
  if (!spec_.is_uint8) throw ImageIoError(state_->path + ": the image does not store 8-bit values");
  check_read_channels(spec_, channels, state_->path);
  const std::vector<uint8_t> data = decode();
  keep_8bit(data.data(), size_t(spec_.width) * size_t(spec_.height), spec_.channels, channels, pixels);
}

std::unique_ptr<AssetDecoder> open_png(const ImageSource& source) { return PngImage::open(source); }

}  // namespace penumbra
