// Image assets from untrusted files: a header that claims more pixels than the limits is refused
// before any pixel is decoded (no allocation of its size), and broken files fail with an error
// naming the file instead of crashing.
#include "renderer/io/image_reader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>
#include <vector>

#include "renderer/io/image_io.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

// CRC-32 of PNG chunks (ISO 3309, as in the PNG specification's sample code).
uint32_t crc32(const std::string& bytes) {
  uint32_t c = 0xffffffffu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xffffffffu;
}

std::string be32(uint32_t v) {
  return {char(v >> 24), char((v >> 16) & 0xff), char((v >> 8) & 0xff), char(v & 0xff)};
}

std::string chunk(const std::string& type, const std::string& data) {
  return be32(uint32_t(data.size())) + type + data + be32(crc32(type + data));
}

// A well-formed PNG header of an 8-bit RGB image of the given size, followed by a few bytes of
// image data: enough for a reader to report the size, far too little for the pixels.
std::string png_claiming(uint32_t width, uint32_t height) {
  const std::string ihdr = be32(width) + be32(height) + std::string("\x08\x02\x00\x00\x00", 5);
  const std::string idat("\x78\x9c\x63\x00\x00\x00\x01\x00\x01", 9);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", idat) +
         chunk("IEND", "");
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// The call throws ImageIoError whose message names the file and contains `reason`, quickly.
template <typename F>
void expect_refused(F&& call, const std::string& path, const std::string& reason) {
  const auto start = std::chrono::steady_clock::now();
  try {
    call();
    ADD_FAILURE() << path << " was accepted";
  } catch (const ImageIoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST(ImageReader, HeaderClaimingTenGigapixelsIsRefusedBeforeDecoding) {
  TempFolder dir("reader_huge");
  const std::string png = dir.file("huge.png");
  write_bytes(png, png_claiming(100000, 100000));
  // The header itself reads fine (the crafted file is valid up to its data)...
  ImageReadLimits unlimited;
  unlimited.max_pixels = int64_t(1) << 40;
  unlimited.max_dimension = 1 << 30;
  const AssetImageInfo info = probe_asset_image(png, unlimited);
  EXPECT_EQ(info.width, 100000);
  EXPECT_EQ(info.height, 100000);
  // ...and under the limits neither probing nor reading gets further than the header: decoding
  // would allocate 120 GB as float.
  expect_refused([&] { probe_asset_image(png); }, png, "at most");
  expect_refused([&] { read_asset_image(png); }, png, "at most");
  // A row of 2^31 - 1 pixels: refused from the header, before libpng sizes its row buffers (6 GB
  // here, cleared when they are made).
  const std::string wide = dir.file("wide.png");
  write_bytes(wide, png_claiming(0x7fffffffu, 1));
  expect_refused([&] { probe_asset_image(wide); }, wide, "at most");
  expect_refused([&] { read_asset_image(wide); }, wide, "at most");
  ImageReadLimits pixels_only;
  pixels_only.max_pixels = 1000 * 1000;
  pixels_only.max_dimension = 1 << 30;
  expect_refused([&] { read_asset_image(png, pixels_only); }, png, "pixels; at most 1000000");
}

TEST(ImageReader, PixelLimitAtTheLimitPassesOneBelowFails) {
  TempFolder dir("reader_limit");
  const std::string png = dir.file("small.png");
  write_test_image(png, 5, 4, 3, std::vector<float>(60, 0.5f), OIIO::TypeDesc::UINT8);
  ImageReadLimits limits;
  limits.max_pixels = 20;
  EXPECT_EQ(read_asset_image(png, limits).pixels.size(), 60u);
  limits.max_pixels = 19;
  expect_refused([&] { read_asset_image(png, limits); }, png, "20 pixels; at most 19");
  limits = ImageReadLimits{};
  limits.max_dimension = 4;
  expect_refused([&] { probe_asset_image(png, limits); }, png, "at most 4 per side");
}

TEST(ImageReader, NetpbmHeaderClaimingHugeSizeIsRefused) {
  TempFolder dir("reader_pgm");
  const std::string pgm = dir.file("huge.pgm");
  write_bytes(pgm, "P5\n200000 200000\n255\n" + std::string(64, '\x7f'));
  expect_refused([&] { read_asset_image(pgm); }, pgm, "at most");
}

TEST(ImageReader, TruncatedGarbageAndEmptyFilesFailWithTheFileNamed) {
  TempFolder dir("reader_broken");
  // A valid 64 x 64 PNG cut off in the middle of its data.
  const std::string good = dir.file("good.png"), cut = dir.file("cut.png");
  std::vector<float> noise(64 * 64 * 3);
  for (size_t i = 0; i < noise.size(); ++i) noise[i] = float((i * 7919) % 256) / 255.f;
  write_test_image(good, 64, 64, 3, noise, OIIO::TypeDesc::UINT8);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_bytes(cut, bytes.substr(0, bytes.size() / 2));
  expect_refused([&] { read_asset_image(cut); }, cut, "");
  const std::string garbage = dir.file("garbage.png"), empty = dir.file("empty.exr");
  write_bytes(garbage, std::string(1000, 'x'));
  write_bytes(empty, "");
  expect_refused([&] { read_asset_image(garbage); }, garbage, "cannot read");
  expect_refused([&] { probe_asset_image(empty); }, empty, "cannot read");
  expect_refused([&] { probe_asset_image(dir.file("missing.png")); }, dir.file("missing.png"),
                 "cannot read");
}

TEST(ImageReader, NonFiniteTexelsBecomeZero) {
  TempFolder dir("reader_nan");
  const std::string exr = dir.file("nan.exr");
  write_test_image(exr, 3, 1, 1, {NAN, INFINITY, 2.f});
  const AssetImage img = read_asset_image(exr);
  EXPECT_EQ(img.pixels, (std::vector<float>{0.f, 0.f, 2.f}));
  EXPECT_TRUE(img.is_float);
}

}  // namespace
}  // namespace penumbra::test
