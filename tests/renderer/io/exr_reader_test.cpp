// EXR assets decoded by OpenEXR (renderer/io/exr_reader.h) against OpenImageIO's reader through the
// plug-in: the same channels and floats for the forms this reader takes (R G B [A], Y [A]; half
// and float; scanline and tiled; a data window away from the origin), the plug-in for every other
// form, from a file and from memory; broken files fail with the source named.
#include "renderer/io/exr_reader.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"
#include "renderer/io/oiio_module.h"
#include "tests/renderer/io/asset_reader_test_util.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

struct ExrKind {
  const char* name;
  std::vector<std::string> channels;  // as written (OpenEXR sorts them by name)
  Imf::PixelType type = Imf::HALF;
  bool tiled = false;
  Imath::V2i origin{0, 0};  // the data window's corner
  bool direct = true;       // decoded by exr_reader (else left to the plug-in)
};

// Value of channel c at pixel i: spread over the half range, signs, fractions, large values.
float value(size_t i, size_t c) {
  const float v = float((i * 2654435761u + c * 40503u) % 20011u) / 97.f - 40.f;
  return c % 2 ? v : v * v;
}

void write_exr(const std::string& path, const ExrKind& kind, int w, int h) {
  const Imath::Box2i data(kind.origin, kind.origin + Imath::V2i(w - 1, h - 1));
  const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(kind.origin.x + w - 1, kind.origin.y + h - 1));
  Imf::Header header(display, data);
  for (const std::string& c : kind.channels) header.channels().insert(c, Imf::Channel(kind.type));
  if (kind.tiled) header.setTileDescription(Imf::TileDescription(16, 8, Imf::ONE_LEVEL));
  const size_t n = size_t(w) * size_t(h), nc = kind.channels.size();
  std::vector<float> f(n * nc);
  std::vector<half> hv(n * nc);
  std::vector<uint32_t> u(n * nc);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < nc; ++c) {
      f[i * nc + c] = value(i, c);
      hv[i * nc + c] = half(value(i, c));
      u[i * nc + c] = uint32_t(i * 7 + c);
    }
  Imf::FrameBuffer frame;
  for (size_t c = 0; c < nc; ++c) {
    const void* base = kind.type == Imf::FLOAT ? static_cast<const void*>(&f[c])
                       : kind.type == Imf::HALF ? static_cast<const void*>(&hv[c])
                                                : static_cast<const void*>(&u[c]);
    const size_t size = kind.type == Imf::HALF ? sizeof(half) : 4;
    frame.insert(kind.channels[c], Imf::Slice::Make(kind.type, base, data, nc * size, nc * size * size_t(w)));
  }
  if (kind.tiled) {
    Imf::TiledOutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
  } else {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(h);
  }
}

const ExrKind kKinds[] = {
    {"rgb_half", {"R", "G", "B"}},
    {"rgba_float", {"R", "G", "B", "A"}, Imf::FLOAT},
    {"y_half", {"Y"}},
    {"ya_float", {"Y", "A"}, Imf::FLOAT},
    {"rgb_float_tiled", {"R", "G", "B"}, Imf::FLOAT, true},
    {"rgba_half_offset", {"R", "G", "B", "A"}, Imf::HALF, false, {5, 3}},
    {"layered", {"diffuse.R", "diffuse.G", "diffuse.B"}, Imf::HALF, false, {0, 0}, false},
    {"rgb_and_depth", {"R", "G", "B", "Z"}, Imf::FLOAT, false, {0, 0}, false},
    {"rgb_uint", {"R", "G", "B"}, Imf::UINT, false, {0, 0}, false},
};

TEST(ExrReader, ExrFilesOfTheCommonFormDoNotLoadTheOpenImageIoPlugin) {
  if (oiio_module_loaded()) GTEST_SKIP() << "an earlier test of this process loaded the plug-in";
  // ctest runs each test in its own process; in one process with others it may be skipped.
  TempFolder dir("exr_no_plugin");
  const std::string path = dir.file("a.exr");
  write_exr(path, kKinds[0], 9, 4);
  EXPECT_EQ(probe_asset_image(path).width, 9);
  EXPECT_EQ(read_asset_image(path).pixels.size(), 9u * 4u * 3u);
  EXPECT_FALSE(oiio_module_loaded());
}

TEST(ExrReader, DecodesAsOpenImageIoDoesBitForBit) {
  TempFolder dir("exr_kinds");
  for (const ExrKind& kind : kKinds) {
    SCOPED_TRACE(kind.name);
    const std::string path = dir.file(std::string(kind.name) + ".exr");
    const int w = 37, h = 21;
    write_exr(path, kind, w, h);
    EXPECT_EQ(open_exr(path) != nullptr, kind.direct);
    auto plugin = open_plugin_image(path);
    const PenumbraImageSpec ref = plugin->spec();
    const int kept = std::min(ref.channels, 4);
    std::vector<float> expected(size_t(w) * size_t(h) * size_t(kept));
    plugin->read(kept, expected.data());
    const AssetImage ours = read_asset_image(path);
    ASSERT_EQ(ours.width, ref.width);
    ASSERT_EQ(ours.height, ref.height);
    ASSERT_EQ(ours.channels, kept);
    EXPECT_TRUE(ours.is_float || kind.type == Imf::UINT);
    int mismatches = 0;
    for (size_t i = 0; i < expected.size(); ++i)
      mismatches += std::memcmp(&ours.pixels[i], &expected[i], sizeof(float)) != 0;
    EXPECT_EQ(mismatches, 0);
    if (kind.direct) {  // and the values are the written ones (half-rounded), R G B A / Y A order
      const size_t nc = size_t(kept);
      for (size_t i = 0; i < size_t(w) * size_t(h); i += 17)
        for (size_t c = 0; c < nc; ++c) {
          const float v = kind.type == Imf::HALF ? float(half(value(i, c))) : value(i, c);
          ASSERT_EQ(ours.pixels[i * nc + c], v) << i << " " << c;
        }
    }
    EXPECT_THROW(read_asset_image_8bit(path), ImageIoError);
  }
}

TEST(ExrReader, ImageInMemoryDecodesAsItsFile) {
  TempFolder dir("exr_memory");
  const std::string path = dir.file("m.exr");
  write_exr(path, kKinds[1], 19, 11);
  const std::string bytes = file_bytes(path);
  const ImageSource source("embedded image 1",
                           std::make_shared<const std::vector<uint8_t>>(bytes.begin(), bytes.end()), "exr");
  EXPECT_NE(open_exr(source), nullptr);
  EXPECT_EQ(read_asset_image(source).pixels, read_asset_image(path).pixels);
}

// A tiled header whose data window is far larger than its pixels: 16 x 8 tiles over 100000 x
// 100000 pixels, 78 million of them, would make OpenEXR allocate a 625 MB offset table before
// reading a tile (1 x 1 tiles: 80 GB).
TEST(ExrReader, HeaderImplyingTooManyTilesIsRefusedBeforeOpenExrSizesThem) {
  TempFolder dir("exr_tiles");
  const std::string path = dir.file("tiles.exr");
  ExrKind kind{"tiny_tiles", {"R", "G", "B"}, Imf::HALF, true};
  write_exr(path, kind, 4, 4);
  std::string bytes = file_bytes(path);
  // The attribute "dataWindow" (box2i, 16 bytes: xMin yMin xMax yMax, little-endian int32).
  const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const size_t value = at + key.size() + 4;
  for (int k = 2; k < 4; ++k) {  // xMax = yMax = 99999
    const uint32_t v = 99999;
    std::memcpy(&bytes[value + 4 * size_t(k)], &v, 4);
  }
  const std::string huge = dir.file("huge.exr");
  std::ofstream(huge, std::ios::binary) << bytes;
  expect_refused_naming([&] { read_asset_image(huge); }, huge, "tiles of 16 x 8 make more than");
}

TEST(ExrReader, BrokenFilesFailWithTheSourceNamed) {
  TempFolder dir("exr_broken");
  const std::string path = dir.file("whole.exr");
  write_exr(path, kKinds[1], 64, 64);
  const std::string bytes = file_bytes(path);
  // Cut in the magic number, the header, the offset table and the pixels.
  expect_files_refused(dir, ".exr", {bytes.substr(0, 6), bytes.substr(0, 30), bytes.substr(0, 200),
                                     bytes.substr(0, bytes.size() / 2), bytes.substr(0, bytes.size() - 9)});
}

}  // namespace
}  // namespace penumbra::test
