// JPEG assets decoded by libjpeg-turbo (renderer/io/jpeg_reader.h) against OpenImageIO's reader
// through the plug-in: RGB (baseline and progressive, 4:4:4 and 4:2:0) and grey, the same values
// bit for bit; CMYK left to the plug-in; from memory as from a file; broken files fail with the
// source named.
#include "renderer/io/jpeg_reader.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"
#include "renderer/io/oiio_module.h"
#include "tests/renderer/io/asset_reader_test_util.h"
#include "tests/renderer/textures/texture_test_util.h"

#include <jpeglib.h>

namespace penumbra::test {
namespace {

// Smooth gradients with sharp edges: every DCT block and chroma subsampling matter.
std::vector<float> picture(int w, int h, int channels) {
  std::vector<float> v(size_t(w) * size_t(h) * size_t(channels));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) {
        const float edge = ((x / 7 + y / 5) % 3 == 0) ? 0.4f : 0.f;
        v[(size_t(y) * size_t(w) + size_t(x)) * size_t(channels) + size_t(c)] =
            std::min(1.f, float(x * (c + 1) + y * (3 - c)) / float(w + h) * 0.6f + edge);
      }
  return v;
}

void write_jpeg(const std::string& path, int w, int h, int channels, const std::string& subsampling,
                bool progressive) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
  spec.attribute("Compression", "jpeg:90");
  if (!subsampling.empty()) spec.attribute("jpeg:subsampling", subsampling);
  if (progressive) spec.attribute("jpeg:progressive", 1);
  const std::vector<float> pixels = picture(w, h, channels);
  ASSERT_TRUE(out->open(path, spec) && out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) && out->close());
}

struct JpegKind {
  const char* name;
  int channels;
  const char* subsampling;
  bool progressive;
};
const JpegKind kKinds[] = {
    {"rgb444", 3, "4:4:4", false},
    {"rgb420", 3, "4:2:0", false},
    {"rgb422_progressive", 3, "4:2:2", true},
    {"grey", 1, "", false},
    {"grey_progressive", 1, "", true},
};

TEST(JpegReader, JpegFilesDoNotLoadTheOpenImageIoPlugin) {
  if (oiio_module_loaded()) GTEST_SKIP() << "an earlier test of this process loaded the plug-in";
  TempFolder dir("jpeg_no_plugin");
  const std::string path = dir.file("a.jpg");
  write_jpeg(path, 9, 5, 3, "4:2:0", false);
  EXPECT_TRUE(probe_asset_image(path).is_8bit);
  EXPECT_EQ(read_asset_image(path).pixels.size(), 9u * 5u * 3u);
  EXPECT_FALSE(oiio_module_loaded());
}

TEST(JpegReader, DecodesAsOpenImageIoDoesBitForBit) {
  TempFolder dir("jpeg_kinds");
  for (const JpegKind& kind : kKinds) {
    SCOPED_TRACE(kind.name);
    const std::string path = dir.file(std::string(kind.name) + ".jpg");
    const int w = 53, h = 37;  // not multiples of the 8x8 blocks or the 16x16 macroblocks
    write_jpeg(path, w, h, kind.channels, kind.subsampling, kind.progressive);
    ASSERT_NE(open_jpeg(path), nullptr);
    auto plugin = open_plugin_image(path);
    ASSERT_EQ(plugin->spec().channels, kind.channels);
    std::vector<float> expected(size_t(w) * size_t(h) * size_t(kind.channels));
    plugin->read(kind.channels, expected.data());
    const AssetImage ours = read_asset_image(path);
    ASSERT_EQ(ours.width, w);
    ASSERT_EQ(ours.height, h);
    ASSERT_EQ(ours.channels, kind.channels);
    ASSERT_EQ(ours.pixels.size(), expected.size());
    int mismatches = 0;
    for (size_t i = 0; i < expected.size(); ++i)
      mismatches += std::memcmp(&ours.pixels[i], &expected[i], sizeof(float)) != 0;
    EXPECT_EQ(mismatches, 0);
    const AssetImage8 raw = read_asset_image_8bit(path);
    for (size_t i = 0; i < raw.pixels.size(); ++i)
      ASSERT_EQ(float(raw.pixels[i]) * (1.f / 255.f), ours.pixels[i]) << i;
  }
}

// A CMYK JPEG (as print workflows write them), through libjpeg: OpenImageIO writes RGB only.
void write_cmyk_jpeg(const std::string& path, int w, int h) {
  jpeg_compress_struct c{};
  jpeg_error_mgr err{};
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  jpeg_stdio_dest(&c, f);
  c.image_width = JDIMENSION(w);
  c.image_height = JDIMENSION(h);
  c.input_components = 4;
  c.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&c);
  jpeg_start_compress(&c, TRUE);
  std::vector<JSAMPLE> row(size_t(w) * 4);
  for (int y = 0; y < h; ++y) {
    for (size_t i = 0; i < row.size(); ++i) row[i] = JSAMPLE((i * 29 + size_t(y) * 7) % 256);
    JSAMPROW p = row.data();
    jpeg_write_scanlines(&c, &p, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::fclose(f);
}

TEST(JpegReader, CmykIsLeftToThePlugin) {
  TempFolder dir("jpeg_cmyk");
  const std::string path = dir.file("cmyk.jpg");
  write_cmyk_jpeg(path, 16, 8);
  EXPECT_EQ(open_jpeg(path), nullptr);
  EXPECT_EQ(read_asset_image(path).channels, 3);  // the plug-in's RGB
}

TEST(JpegReader, ImageInMemoryDecodesAsItsFile) {
  TempFolder dir("jpeg_memory");
  const std::string path = dir.file("m.jpg");
  write_jpeg(path, 21, 13, 3, "4:2:0", true);
  const std::string bytes = file_bytes(path);
  const ImageSource source("embedded image 0",
                           std::make_shared<const std::vector<uint8_t>>(bytes.begin(), bytes.end()), "jpeg");
  EXPECT_EQ(read_asset_image(source).pixels, read_asset_image(path).pixels);
}

TEST(JpegReader, BrokenFilesFailWithTheSourceNamed) {
  TempFolder dir("jpeg_broken");
  const std::string path = dir.file("whole.jpg");
  write_jpeg(path, 64, 64, 3, "4:2:0", false);
  const std::string bytes = file_bytes(path);
  // Cut inside the header: an error. (Cut inside the entropy-coded data, libjpeg fills the rest
  // with grey and warns, as OpenImageIO reads it: not an error.)
  expect_files_refused(dir, ".jpg", {bytes.substr(0, 3), bytes.substr(0, 20), bytes.substr(0, 150)});
}

}  // namespace
}  // namespace penumbra::test
