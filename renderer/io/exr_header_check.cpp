#include "renderer/io/exr_header_check.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "renderer/io/image_io.h"

namespace penumbra {
namespace {

// The size of OpenEXR's fixed-layout attribute types (ImfStandardAttributes, ImfAttribute.cpp's
// type list); -1 for variable-length ones (string, chlist, stringvector, preview, opaque).
int fixed_attribute_size(const std::string& type) {
  static const std::pair<const char*, int> kSizes[] = {
      {"int", 4},      {"float", 4},     {"double", 8},      {"v2i", 8},         {"v2f", 8},
      {"v2d", 16},     {"v3i", 12},      {"v3f", 12},        {"v3d", 24},        {"box2i", 16},
      {"box2f", 16},   {"m33f", 36},     {"m33d", 72},       {"m44f", 64},       {"m44d", 128},
      {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"chromaticities", 32}, {"rational", 8}, {"timecode", 8}, {"keycode", 28}, {"tiledesc", 9}};
  for (const auto& [name, size] : kSizes)
    if (type == name) return size;
  return -1;
}

uint32_t le32(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

// OpenEXR 3.1 sizes a tiled file's offset table by the tile count its header implies before it
// reads a tile: 1 x 1 tiles over a 100k x 100k window would be 80 GB. Refused above 2^22 tiles
// (32 MB of offsets; a 65536 x 65536 image in 32 x 32 tiles), counting every level of a mipmap
// (at most twice the first level's) or ripmap (four times).
constexpr uint64_t kMaxExrTiles = uint64_t(1) << 22;

void check_tile_count(bool tiled, int64_t w, int64_t h, uint32_t tile_w, uint32_t tile_h,
                      uint32_t level_mode, const std::string& path) {
  if (!tiled) return;
  if (tile_w == 0 || tile_h == 0) throw ImageIoError(path + ": the tile description has a tile of size 0");
  if (w <= 0 || h <= 0) return;  // OpenEXR refuses an empty or inverted window itself
  const uint64_t nx = (uint64_t(w) + tile_w - 1) / tile_w, ny = (uint64_t(h) + tile_h - 1) / tile_h;
  const uint64_t levels_factor = level_mode == 0 ? 1 : level_mode == 1 ? 2 : 4;
  if (nx > kMaxExrTiles || ny > kMaxExrTiles || nx * ny * levels_factor > kMaxExrTiles)
    throw ImageIoError(path + ": the image's " + std::to_string(w) + " x " + std::to_string(h) +
                       " pixels in tiles of " + std::to_string(tile_w) + " x " + std::to_string(tile_h) +
                       " make more than " + std::to_string(kMaxExrTiles) + " tiles");
}

// OpenEXR 3.1 also sizes a scanline file's decompression buffers by the header before it reads
// a pixel: a chunk's lines (1 to 256 by compression) times the widest line's bytes (the data
// window's width times the channels' sample sizes). A 688-byte file with an 8-million-pixel-wide
// window of four float channels under ZIP made it allocate 2.1 GB (found by the exr_window
// fuzzer); a tile's buffer is its tile's pixels times the same bytes. Refused above 256 MiB
// (a 16384-wide image of 16 float channels under DWAB is 256 MiB; real files are far below).
// The scanline offset table, one 8-byte entry per chunk of lines, must also fit in the file.
constexpr uint64_t kMaxExrChunkBytes = uint64_t(256) << 20;

// Lines per chunk of each compression (OpenEXR's ImfCompression.h, numLinesInBuffer).
uint64_t lines_per_chunk(uint32_t compression) {
  constexpr uint64_t kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  return compression < std::size(kLines) ? kLines[compression] : 256;  // unknown: the largest
}

void check_buffer_sizes(bool tiled, int64_t w, int64_t h, uint32_t tile_w, uint32_t tile_h,
                        uint64_t sample_bytes, uint32_t compression, uint64_t file_size,
                        const std::string& path) {
  if (w <= 0 || h <= 0) return;  // OpenEXR refuses an empty or inverted window itself
  const uint64_t chunk = tiled ? uint64_t(tile_w) * uint64_t(tile_h) * sample_bytes
                               : uint64_t(w) * sample_bytes * lines_per_chunk(compression);
  if (chunk > kMaxExrChunkBytes)
    throw ImageIoError(path + ": a " + (tiled ? "tile" : "chunk of lines") + " of the " +
                       std::to_string(w) + " x " + std::to_string(h) + " pixel image would take " +
                       std::to_string(chunk) + " bytes to decode, over " + std::to_string(kMaxExrChunkBytes));
  if (!tiled && (uint64_t(h) + lines_per_chunk(compression) - 1) / lines_per_chunk(compression) * 8 > file_size)
    throw ImageIoError(path + ": the " + std::to_string(h) + " lines' offset table is larger than the file");
}

}  // namespace

// OpenEXR 3.1 allocates an attribute's value at the size the file declares before reading it, so
// a 40-byte file can make it allocate 2 GB (found by the exr_window fuzzer). Walk the header
// first (OpenEXR file layout: magic, version, then name\0 type\0 int32 size value, up to a
// null byte) and refuse any size beyond the bytes the file holds. `head` is the file's start,
// at most kMaxExrHeaderBytes; `file_size` the whole file's.
uint32_t check_exr_header(const uint8_t* head, size_t head_size, uint64_t file_size, const std::string& path) {
  if (head_size < 8 || le32(head) != 20000630u) throw ImageIoError(path + ": not an OpenEXR file");
  const uint32_t flags = le32(head + 4);
  // Their headers are laid out otherwise: the caller decides what to do with them.
  if (flags & (kExrMultiPart | kExrDeep)) return flags;
  size_t pos = 8;
  auto skip_text = [&](const char* what) {
    const size_t end = std::min(head_size, pos + 256);
    const uint8_t* zero = static_cast<const uint8_t*>(std::memchr(head + pos, 0, end - pos));
    if (!zero) throw ImageIoError(path + ": the header's attribute " + what + " is unterminated or too long");
    pos = size_t(zero - head) + 1;
  };
  // The data window and the tile description, for the tile count below. Whether OpenEXR reads
  // the file as tiles or as lines is the version field's tiled flag, not the presence of a
  // "tiles" attribute (a scanline file may carry one as any other attribute: sizing its lines'
  // buffers by its tiles let a fuzzed file through to a 2.1 GB allocation).
  int64_t window_w = 0, window_h = 0;
  uint32_t tile_w = 0, tile_h = 0, level_mode = 0;
  const bool tiled = (flags & kExrTiled) != 0;
  bool has_tiles = false;
  // The channels' bytes per pixel (half: 2, float and uint: 4; subsampling ignored, which only
  // overestimates) and the compression, for the decode buffers' sizes.
  // A file without a "compression" attribute is read as ZIP, OpenEXR's Header() default, 16
  // lines per chunk (a fuzzed file whose attribute name was altered hid its 2.1 GB this way).
  uint64_t sample_bytes = 0;
  uint32_t compression = 3;
  while (true) {
    if (pos >= head_size)
      throw ImageIoError(path + ": the header is truncated or larger than " + std::to_string(kMaxExrHeaderBytes) + " bytes");
    if (head[pos] == 0) {
      if (tiled && !has_tiles) throw ImageIoError(path + ": a tiled file without a tile description");
      check_tile_count(tiled, window_w, window_h, tile_w, tile_h, level_mode, path);
      check_buffer_sizes(tiled, window_w, window_h, tile_w, tile_h, sample_bytes, compression, file_size, path);
      return flags;
    }
    const size_t name_at = pos;
    skip_text("name");
    const std::string name(reinterpret_cast<const char*>(head + name_at));
    skip_text("type");
    if (pos + 4 > head_size) throw ImageIoError(path + ": the header is truncated");
    const int32_t size = int32_t(le32(head + pos));
    pos += 4;
    if (size < 0 || uint64_t(size) > file_size - pos)
      throw ImageIoError(path + ": header attribute \"" + name + "\" claims " + std::to_string(size) +
                         " bytes, more than the file holds");
    // OpenEXR reads typed values by their own layout, not by the declared size: the two must
    // agree, or its reading and this walk part ways and a later size goes unchecked.
    const std::string type(reinterpret_cast<const char*>(head + name_at + name.size() + 1));
    const uint8_t* value = head + pos;
    const size_t available = std::min<size_t>(size_t(size), head_size - std::min(head_size, pos));
    auto bad = [&](const char* why) {
      return ImageIoError(path + ": header attribute \"" + name + "\" (" + type + "): " + why);
    };
    if (const int fixed = fixed_attribute_size(type); fixed >= 0) {
      if (size != fixed) throw bad("wrong size");
      if (available == size_t(size) && name == "dataWindow" && type == "box2i") {
        window_w = int64_t(int32_t(le32(value + 8))) - int32_t(le32(value)) + 1;
        window_h = int64_t(int32_t(le32(value + 12))) - int32_t(le32(value + 4)) + 1;
      } else if (available == size_t(size) && name == "compression" && type == "compression") {
        compression = value[0];
      } else if (available == size_t(size) && name == "tiles" && type == "tiledesc") {
        has_tiles = true;
        tile_w = le32(value);
        tile_h = le32(value + 4);
        level_mode = value[8] & 0x0fu;
      }
    } else if (type == "chlist") {
      // Entries "name\0" + 16 bytes, then a null byte ending exactly at the declared size.
      size_t at = 0;
      while (at < available && value[at] != 0) {
        const uint8_t* zero = static_cast<const uint8_t*>(std::memchr(value + at, 0, available - at));
        if (!zero) throw bad("unterminated channel name");
        at = size_t(zero - value) + 1;
        if (name == "channels" && at + 4 <= available) sample_bytes += le32(value + at) == 1 ? 2 : 4;
        at += 16;
      }
      if (at + 1 != size_t(size) || at >= available) throw bad("channel list does not fill its size");
    } else if (type == "stringvector") {
      size_t at = 0;
      while (at < size_t(size)) {
        if (at + 4 > available) throw bad("truncated");
        const int32_t n = int32_t(le32(value + at));
        if (n < 0 || size_t(n) > size_t(size) - at - 4) throw bad("a string beyond the attribute");
        at += 4 + size_t(n);
      }
    } else if (type == "preview") {
      if (available < 8 || size_t(size) != 8 + 4 * uint64_t(le32(value)) * le32(value + 4)) throw bad("wrong size");
    }
    pos += size_t(size);
  }
}

uint32_t check_exr_file_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ImageIoError(path + ": cannot open the file");
  in.seekg(0, std::ios::end);
  const uint64_t file_size = uint64_t(std::max<std::streamoff>(0, in.tellg()));
  in.seekg(0);
  std::vector<uint8_t> head(size_t(std::min<uint64_t>(file_size, kMaxExrHeaderBytes)));
  in.read(reinterpret_cast<char*>(head.data()), std::streamsize(head.size()));
  if (!in) throw ImageIoError(path + ": cannot read the file");
  return check_exr_header(head.data(), head.size(), file_size, path);
}

ExrMemoryStream::ExrMemoryStream(const std::string& name, const std::vector<uint8_t>& bytes)
    : Imf::IStream(name.c_str()), bytes_(bytes) {}

bool ExrMemoryStream::read(char c[], int n) {
  // pos_ comes from seekg, i.e. from offsets in the file: compare without overflowing.
  if (n < 0 || pos_ > bytes_.size() || uint64_t(n) > bytes_.size() - pos_)
    throw std::runtime_error("unexpected end of file");
  std::memcpy(c, bytes_.data() + pos_, size_t(n));
  pos_ += uint64_t(n);
  return pos_ < bytes_.size();
}

}  // namespace penumbra
