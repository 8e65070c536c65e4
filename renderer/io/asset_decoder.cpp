#include "renderer/io/asset_decoder.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "renderer/io/image_reader.h"

namespace penumbra {

SourceHead read_source_head(const ImageSource& source) {
  SourceHead head;
  if (source.bytes) {
    head.size = std::min(sizeof head.bytes, source.bytes->size());
    if (head.size > 0) std::memcpy(head.bytes, source.bytes->data(), head.size);  // data() may be null
  } else if (std::FILE* f = std::fopen(source.path.c_str(), "rb")) {
    head.size = std::fread(head.bytes, 1, sizeof head.bytes, f);
    std::fclose(f);
  }
  return head;
}

}  // namespace penumbra
