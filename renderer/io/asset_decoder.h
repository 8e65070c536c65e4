#pragma once
// An image asset opened by one of the readers image_reader.cpp chooses between by the file's
// first bytes (png_reader, exr_reader, hdr_reader, jpeg_reader, or the OpenImageIO plug-in,
// oiio_module): its header read, its pixels decoded by read().
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "renderer/io/oiio_plugin/oiio_plugin_abi.h"

namespace penumbra {

struct ImageSource;

class AssetDecoder {
 public:
  virtual ~AssetDecoder() = default;
  virtual const PenumbraImageSpec& spec() const = 0;
  // The first `channels` channels (at most spec().channels), channel-interleaved, top row
  // first, as float or as the stored 8-bit values (8-bit images only). Throws ImageIoError.
  virtual void read(int channels, float* pixels) = 0;
  virtual void read(int channels, uint8_t* pixels) = 0;
};

// A source's first bytes, which the readers' signatures are checked on: `size` is less than 8
// where the data is shorter, 0 where the file cannot be read (its error then comes from the
// reader that is tried).
struct SourceHead {
  uint8_t bytes[8] = {};
  size_t size = 0;
};
SourceHead read_source_head(const ImageSource& source);

// The bytes of a source, a file or memory, read in order (the readers that take their input a
// few bytes at a time: png_reader's libpng callback, hdr_reader).
class SourceReader {
 public:
  explicit SourceReader(const ImageSource& source);
  ~SourceReader();
  SourceReader(const SourceReader&) = delete;
  SourceReader& operator=(const SourceReader&) = delete;
  bool ok() const { return bytes_ || file_; }  // false: the file cannot be opened
  // Reads up to n bytes; how many there were.
  size_t read_up_to(uint8_t* out, size_t n);
  // Reads n bytes; false at the end of the data.
  bool read(uint8_t* out, size_t n) { return read_up_to(out, n) == n; }
  int get() {  // one byte, or -1 at the end
    uint8_t c;
    return read(&c, 1) ? c : -1;
  }

 private:
  std::shared_ptr<const std::vector<uint8_t>> bytes_;  // an image in memory: kept alive
  std::FILE* file_ = nullptr;
  size_t offset_ = 0;
};

// What the decoders of 8-bit images share. Throws ImageIoError naming `path` unless
// 1 <= channels <= spec.channels (read()'s precondition).
void check_read_channels(const PenumbraImageSpec& spec, int channels, const std::string& path);
// The first `kept` of `stored` interleaved channels of `pixels` pixels: as float, value * (1/255)
// (OpenImageIO's conversion, not value / 255, which differs in the last bit for some values), or
// as the 8-bit values themselves.
void widen_8bit(const uint8_t* data, size_t pixels, int stored, int kept, float* out);
void keep_8bit(const uint8_t* data, size_t pixels, int stored, int kept, uint8_t* out);

}  // namespace penumbra
