// Radiance HDR assets decoded by renderer/io/hdr_reader against OpenImageIO's reader through the
// plug-in: run-length encoded files (written by OpenImageIO), flat files and narrow images
// (written here), the same floats; other orientations left to the plug-in; broken files fail with
// the source named.
#include "renderer/io/hdr_reader.h"

#include <gtest/gtest.h>

#include <cmath>
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

namespace penumbra::test {
namespace {

// Radiant values over many decades, with runs (equal neighbours) that RLE compresses.
std::vector<float> radiance(int w, int h) {
  std::vector<float> v(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < v.size(); ++i) {
    const size_t run = (i / 3) / 5;  // five equal pixels in a row
    v[i] = std::ldexp(float(run * 2654435761u % 997u) / 997.f, int(run % 40) - 20) * float(1 + i % 3);
  }
  return v;
}

// A flat (not run-length encoded) file: header, resolution line, 4-byte RGBE pixels.
std::string flat_hdr(int w, int h, const std::string& resolution = "") {
  std::string out = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n";
  out += resolution.empty() ? "-Y " + std::to_string(h) + " +X " + std::to_string(w) + "\n" : resolution + "\n";
  for (int i = 0; i < w * h; ++i) {
    const int e = 100 + i % 60;
    out += {char(i * 37 % 256), char(i * 11 % 256), char(i * 5 % 256), char(i % 7 == 0 ? 0 : e)};
  }
  return out;
}

std::vector<float> plugin_pixels(const std::string& path) {
  auto image = open_plugin_image(path);
  std::vector<float> out(size_t(image->spec().width) * size_t(image->spec().height) * 3);
  image->read(3, out.data());
  return out;
}

void expect_same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  ASSERT_EQ(a.size(), b.size());
  int mismatches = 0;
  for (size_t i = 0; i < a.size(); ++i) mismatches += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
  EXPECT_EQ(mismatches, 0);
}

TEST(HdrReader, HdrFilesDoNotLoadTheOpenImageIoPlugin) {
  if (oiio_module_loaded()) GTEST_SKIP() << "an earlier test of this process loaded the plug-in";
  TempFolder dir("hdr_no_plugin");
  const std::string path = dir.file("a.hdr");
  std::ofstream(path, std::ios::binary) << flat_hdr(5, 3);
  EXPECT_EQ(probe_asset_image(path).width, 5);
  EXPECT_TRUE(probe_asset_image(path).is_float);
  EXPECT_EQ(read_asset_image(path).pixels.size(), 5u * 3u * 3u);
  EXPECT_FALSE(oiio_module_loaded());
}

TEST(HdrReader, RunLengthEncodedFilesDecodeAsOpenImageIoDoesBitForBit) {
  TempFolder dir("hdr_rle");
  // 8: the narrowest RLE scanline. 300 x 500: scanlines are decoded in blocks of 218
  // (renderer/core/row_blocks.h), here two and a shorter third, turned into floats on all cores.
  for (const auto& [w, h] : {std::pair{8, 13}, std::pair{61, 13}, std::pair{300, 13}, std::pair{300, 500}}) {
    SCOPED_TRACE(w);
    const std::string path = dir.file("rle" + std::to_string(w) + "x" + std::to_string(h) + ".hdr");
    write_test_image(path, w, h, 3, radiance(w, h));
    ASSERT_NE(open_hdr(path), nullptr);
    const AssetImage ours = read_asset_image(path);
    EXPECT_EQ(ours.width, w);
    EXPECT_EQ(ours.channels, 3);
    expect_same_bits(ours.pixels, plugin_pixels(path));
    // And close to what was written (RGBE keeps 8 bits of mantissa per component).
    const std::vector<float> written = radiance(w, h);
    for (size_t i = 0; i < written.size(); ++i)
      ASSERT_NEAR(ours.pixels[i], written[i], 0.02f * std::max({written[i - i % 3], written[i - i % 3 + 1], written[i - i % 3 + 2]}) + 1e-30f) << i;
  }
}

TEST(HdrReader, FlatFilesAndNarrowImagesDecodeAsOpenImageIoDoes) {
  TempFolder dir("hdr_flat");
  // 5: too narrow for RLE; 5 x 30000: three blocks of scanlines (13107 a block), the last shorter.
  for (const auto& [w, h] : {std::pair{5, 4}, std::pair{64, 3}, std::pair{5, 30000}}) {
    const std::string path = dir.file("flat" + std::to_string(w) + "x" + std::to_string(h) + ".hdr");
    std::ofstream(path, std::ios::binary) << flat_hdr(w, h);
    expect_same_bits(read_asset_image(path).pixels, plugin_pixels(path));
  }
}

TEST(HdrReader, OtherOrientationsAreLeftToThePlugin) {
  TempFolder dir("hdr_orientation");
  const std::string path = dir.file("up.hdr");
  std::ofstream(path, std::ios::binary) << flat_hdr(4, 2, "+Y 2 +X 4");
  EXPECT_EQ(open_hdr(path), nullptr);
}

TEST(HdrReader, BrokenFilesFailWithTheSourceNamed) {
  TempFolder dir("hdr_broken");
  const std::string whole = dir.file("whole.hdr");
  write_test_image(whole, 40, 10, 3, radiance(40, 10));
  const std::string bytes = file_bytes(whole);
  // Scanlines are read in blocks (218 of 300 pixels): cut short or broken in a later block too.
  const std::string tall = dir.file("tall.hdr");
  write_test_image(tall, 300, 500, 3, radiance(300, 500));
  const std::string tall_bytes = file_bytes(tall);
  const std::string one_row = "#?RADIANCE\n\n-Y 1 +X 8\n";  // then an RLE scanline's bytes
  expect_files_refused(dir, ".hdr", {
      bytes.substr(0, 12),                 // inside the header
      bytes.substr(0, bytes.size() / 2),   // inside the pixels
      bytes.substr(0, bytes.size() - 1),
      tall_bytes.substr(0, tall_bytes.size() * 3 / 4),  // in the second block
      tall_bytes.substr(0, tall_bytes.size() - 1),       // in the last, shorter block
      "#?RADIANCE\n\n-Y 2 +X\n",           // bad resolution line
      "#?RADIANCE\n\n-Y -2 +X 4\n",
      one_row + std::string("\x02\x02\x00\x09", 4),              // a scanline wider than the image
      one_row + std::string("\x02\x02\x00\x08\x00", 5),          // a count of 0
      one_row + std::string("\x02\x02\x00\x08\x80", 5),          // 128 literals in 8 pixels
      one_row + std::string("\x02\x02\x00\x08\x89\x01", 6),      // a run past the scanline's end
      one_row + std::string("\x02\x02\x00\x08\x05\x01\x02", 7),  // literals cut short
      "#?RADIANCE\n" + std::string(70000, 'x'),  // a header that never ends
  });
}

}  // namespace
}  // namespace penumbra::test
