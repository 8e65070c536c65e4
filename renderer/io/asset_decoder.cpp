#include "renderer/io/asset_decoder.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"

namespace penumbra {

SourceHead read_source_head(const ImageSource& source) {
  SourceHead head;
  SourceReader in(source);
  if (in.ok()) head.size = in.read_up_to(head.bytes, sizeof head.bytes);
  return head;
}

SourceReader::SourceReader(const ImageSource& source) : bytes_(source.bytes) {
  if (!bytes_) file_ = std::fopen(source.path.c_str(), "rb");
}

SourceReader::~SourceReader() {
  if (file_) std::fclose(file_);
}

size_t SourceReader::read_up_to(uint8_t* out, size_t n) {
  if (file_) return std::fread(out, 1, n, file_);
  if (!bytes_) return 0;
  n = std::min(n, bytes_->size() - offset_);
  if (n > 0) std::memcpy(out, bytes_->data() + offset_, n);  // data() may be null when empty
  offset_ += n;
  return n;
}

void check_read_channels(const PenumbraImageSpec& spec, int channels, const std::string& path) {
  if (channels < 1 || channels > spec.channels) throw ImageIoError(path + ": no such channels");
}

void widen_8bit(const uint8_t* data, size_t pixels, int stored, int kept, float* out) {
  const float scale = 1.f / 255.f;
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < kept; ++c)
      out[i * size_t(kept) + size_t(c)] = float(data[i * size_t(stored) + size_t(c)]) * scale;
}

void keep_8bit(const uint8_t* data, size_t pixels, int stored, int kept, uint8_t* out) {
  for (size_t i = 0; i < pixels; ++i)
    std::memcpy(out + i * size_t(kept), data + i * size_t(stored), size_t(kept));
}

}  // namespace penumbra
