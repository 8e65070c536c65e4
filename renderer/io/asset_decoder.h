#pragma once
// An image asset opened by one of the readers image_reader.cpp chooses between by the file's
// first bytes (png_reader, exr_reader, hdr_reader, jpeg_reader, or the OpenImageIO plug-in,
// oiio_module): its header read, its pixels decoded by read().
#include <cstddef>
#include <cstdint>

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

}  // namespace penumbra
