#include "renderer/io/jpeg_reader.h"

// jpeglib.h needs size_t and FILE declared before it.
#include <cstddef>
#include <cstdio>
#include <csetjmp>
#include <cstring>
#include <string>
#include <vector>

#include <jpeglib.h>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"

namespace penumbra {

// The decoder open_jpeg returns (the header declares only that).
namespace {
class JpegImage final : public AssetDecoder {
 public:
  // open_jpeg (jpeg_reader.h).
  static std::unique_ptr<JpegImage> open(const ImageSource& source);
  ~JpegImage();
  JpegImage(const JpegImage&) = delete;
  JpegImage& operator=(const JpegImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // The first `channels` channels, channel-interleaved, top row first: as float (value / 255,
  // computed as OpenImageIO does) or as the decoded 8-bit values.
  void read(int channels, float* pixels) override;
  void read(int channels, uint8_t* pixels) override;

 struct State;  // libjpeg's state (jpeg_reader.cpp)

 private:
  explicit JpegImage(std::unique_ptr<State> state);
  std::vector<uint8_t> decode();
  std::unique_ptr<State> state_;
  PenumbraImageSpec spec_{};
};


// A progressive JPEG may hold any number of scans, each a pass over the whole coefficient
// buffer: a small file can cost minutes of CPU. libjpeg-turbo's djpeg -maxscan guards against it
// the same way (a progress monitor counting scans); real files have at most a few dozen.
constexpr int kMaxScans = 500;

// What libjpeg's callbacks reach: its error manager first (the callbacks get it as cinfo->err),
// the setjmp point of the call in progress and the last message.
struct JpegErrors {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = "";
};

// libjpeg's contract: error_exit must not return. Nothing is printed (hostile files must not
// write to the service's log); warnings (corrupt but decodable data) are ignored, as
// OpenImageIO does.
[[noreturn]] void on_error(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}
void on_message(j_common_ptr, int) {}

void on_progress(j_common_ptr cinfo) {
  auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (d->is_decompressor && d->input_scan_number > kMaxScans) {
    auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
    std::snprintf(errors->message, sizeof errors->message, "more than %d scans", kMaxScans);
    std::longjmp(errors->jump, 1);
  }
}

}  // namespace

struct JpegImage::State {
  std::string path;
  std::shared_ptr<const std::vector<uint8_t>> bytes;  // an image in memory: kept alive
  std::FILE* file = nullptr;
  JpegErrors errors;
  jpeg_progress_mgr progress{};
  jpeg_decompress_struct cinfo{};
  bool created = false;
  ~State() {
    if (created) jpeg_destroy_decompress(&cinfo);
    if (file) std::fclose(file);
  }
};

namespace {

// The libjpeg calls that may fail, each behind its own setjmp point: these frames hold nothing
// with a destructor and change no local after setjmp, so an error's longjmp is well defined.
bool read_header(JpegErrors* errors, jpeg_decompress_struct* cinfo) {
  if (setjmp(errors->jump)) return false;
  jpeg_read_header(cinfo, TRUE);
  return true;
}

// Creates the decompressor and attaches the source.
bool start(JpegImage::State* s) {
  if (setjmp(s->errors.jump)) return false;
  jpeg_create_decompress(&s->cinfo);
  s->created = true;
  if (s->bytes)
    jpeg_mem_src(&s->cinfo, s->bytes->data(), static_cast<unsigned long>(s->bytes->size()));
  else
    jpeg_stdio_src(&s->cinfo, s->file);
  s->cinfo.progress = &s->progress;
  return true;
}

bool decode_rows(JpegErrors* errors, jpeg_decompress_struct* cinfo, uint8_t* data, size_t row_bytes) {
  if (setjmp(errors->jump)) return false;
  jpeg_start_decompress(cinfo);
  while (cinfo->output_scanline < cinfo->output_height) {
    JSAMPROW row = data + size_t(cinfo->output_scanline) * row_bytes;
    jpeg_read_scanlines(cinfo, &row, 1);
  }
  jpeg_finish_decompress(cinfo);
  return true;
}

}  // namespace

bool has_jpeg_signature(const SourceHead& head) {
  const uint8_t* b = head.bytes;
  return head.size >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff;
}

JpegImage::JpegImage(std::unique_ptr<State> state) : state_(std::move(state)) {}
JpegImage::~JpegImage() = default;

std::unique_ptr<JpegImage> JpegImage::open(const ImageSource& source) {
  auto s = std::make_unique<State>();
  s->path = source.path;
  if (!source.bytes) {
    s->file = std::fopen(source.path.c_str(), "rb");
    if (!s->file) throw ImageIoError(source.path + ": cannot open the file");
  }
  s->bytes = source.bytes;
  s->cinfo.err = jpeg_std_error(&s->errors.mgr);
  s->errors.mgr.error_exit = on_error;
  s->errors.mgr.emit_message = on_message;
  s->progress.progress_monitor = on_progress;
  if (!start(s.get()) || !read_header(&s->errors, &s->cinfo))
    throw ImageIoError(source.path + ": cannot read the image: " + s->errors.message);
  const J_COLOR_SPACE space = s->cinfo.jpeg_color_space;
  if (space == JCS_CMYK || space == JCS_YCCK) return nullptr;
  const bool grey = s->cinfo.num_components == 1;
  s->cinfo.out_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
  auto image = std::unique_ptr<JpegImage>(new JpegImage(std::move(s)));
  const jpeg_decompress_struct& c = image->state_->cinfo;
  image->spec_ = PenumbraImageSpec{int(c.image_width), int(c.image_height), 1, grey ? 1 : 3, 0, 1};
  return image;
}

std::vector<uint8_t> JpegImage::decode() {
  State& s = *state_;
  const size_t row_bytes = size_t(spec_.width) * size_t(spec_.channels);
  std::vector<uint8_t> data(row_bytes * size_t(spec_.height));
  if (!decode_rows(&s.errors, &s.cinfo, data.data(), row_bytes))
    throw ImageIoError(s.path + ": cannot decode the image: " + s.errors.message);
  if (int(s.cinfo.output_width) != spec_.width || int(s.cinfo.output_height) != spec_.height ||
      s.cinfo.output_components != spec_.channels)
    throw ImageIoError(s.path + ": cannot decode the image: unexpected output size");
  return data;
}

void JpegImage::read(int channels, float* pixels) {
  check_read_channels(spec_, channels, state_->path);
  const std::vector<uint8_t> data = decode();
  widen_8bit(data.data(), size_t(spec_.width) * size_t(spec_.height), spec_.channels, channels, pixels);
}

void JpegImage::read(int channels, uint8_t* pixels) {
  check_read_channels(spec_, channels, state_->path);
  const std::vector<uint8_t> data = decode();
  keep_8bit(data.data(), size_t(spec_.width) * size_t(spec_.height), spec_.channels, channels, pixels);
}

std::unique_ptr<AssetDecoder> open_jpeg(const ImageSource& source) { return JpegImage::open(source); }

}  // namespace penumbra
