// A window of a frame as an EXR data window: written by encode_layered_exr, read back by
// read_exr_window (the same pixels, window and layers, either layout; OpenImageIO sees the data
// window inside the display window), and files that are not windows penumbra can merge.
#include <gtest/gtest.h>

#include <algorithm>

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/filesystem.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "renderer/io/exr_window_file.h"
#include "renderer/io/exr_writer.h"
#include "renderer/io/image_io.h"
#include "renderer/io/layer_io.h"

namespace penumbra::test {
namespace {

const PixelWindow kWindow{3, 2, 8, 6};  // 5 x 4 pixels of a 10 x 7 frame
const PixelWindow kFrame{0, 0, 10, 7};

Image window_image() {
  Image img(kWindow.width(), kWindow.height());
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = 0.25f * float(i) + 0.125f;
  return img;
}

std::vector<ImageLayer> window_layers() {
  const size_t n = size_t(kWindow.pixel_count());
  ImageLayer albedo{"albedo", ImageLayer::Kind::kColor, 3, std::vector<float>(3 * n)};
  ImageLayer depth{"depth", ImageLayer::Kind::kDepth, 1, std::vector<float>(n)};
  for (size_t i = 0; i < 3 * n; ++i) albedo.data[i] = float(i) / float(3 * n);
  for (size_t i = 0; i < n; ++i) depth.data[i] = 2.f + float(i);
  return {albedo, depth};
}

bool same(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(ExrWindowFile, RoundTripsTheWindowAndLayersInBothLayouts) {
  for (ExrLayout layout : {ExrLayout::kPlain, ExrLayout::kBlender}) {
    const std::vector<uint8_t> bytes = encode_layered_exr(window_image(), window_layers(), layout,
                                                          {{"penumbra:seed", "7"}}, &kWindow, &kFrame);
    const ExrWindowFile f = read_exr_window("part.exr", bytes);
    EXPECT_EQ(f.display, kFrame);
    EXPECT_EQ(f.part.window, kWindow);
    EXPECT_EQ(f.layout, layout);
    EXPECT_TRUE(same(f.part.image.rgb, window_image().rgb));
    ASSERT_EQ(f.part.layers.size(), 2u);
    EXPECT_EQ(f.part.layers[0].name, "albedo");
    EXPECT_TRUE(same(f.part.layers[0].data, window_layers()[0].data));
    EXPECT_EQ(f.part.layers[1].name, "depth");
    EXPECT_TRUE(same(f.part.layers[1].data, window_layers()[1].data));
    bool seed = false;
    for (const auto& [k, v] : f.metadata) seed |= k == "penumbra:seed" && v == "7";
    EXPECT_TRUE(seed);
  }
}

// Other readers see a crop of the frame where it belongs, as a Nuke or Blender crop.
TEST(ExrWindowFile, OpenImageIOSeesTheDataWindowInsideTheDisplayWindow) {
  std::vector<uint8_t> bytes = encode_layered_exr(window_image(), {}, ExrLayout::kPlain, {}, &kWindow, &kFrame);
  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  auto in = OIIO::ImageInput::open("part.exr", nullptr, &reader);
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  EXPECT_EQ(spec.x, 3);
  EXPECT_EQ(spec.y, 2);
  EXPECT_EQ(spec.width, 5);
  EXPECT_EQ(spec.height, 4);
  EXPECT_EQ(spec.full_x, 0);
  EXPECT_EQ(spec.full_y, 0);
  EXPECT_EQ(spec.full_width, 10);
  EXPECT_EQ(spec.full_height, 7);
  std::vector<float> pixels(size_t(5 * 4 * 3));
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
  EXPECT_TRUE(same(pixels, window_image().rgb));
}

TEST(ExrWindowFile, AWholeImageIsAWindowOfItself) {
  const Image img = window_image();
  const ExrWindowFile f = read_exr_window("whole.exr", encode_layered_exr(img, {}, ExrLayout::kPlain));
  EXPECT_EQ(f.display, (PixelWindow{0, 0, img.width, img.height}));
  EXPECT_EQ(f.part.window, f.display);
}

void expect_error(const std::vector<uint8_t>& bytes, const std::string& fragment,
                  const ExrWindowLimits& limits = {}) {
  try {
    read_exr_window("bad.exr", bytes, limits);
    FAIL() << "read a bad file; expected: " << fragment;
  } catch (const ImageIoError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("bad.exr: ", 0), 0u) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

TEST(ExrWindowFile, FilesThatAreNotWindowsAreErrorsNamingTheFile) {
  const std::vector<uint8_t> good =
      encode_layered_exr(window_image(), window_layers(), ExrLayout::kPlain, {}, &kWindow, &kFrame);
  // Truncated anywhere: an error, never a crash.
  for (size_t n : {size_t(0), size_t(4), size_t(100), good.size() / 2, good.size() - 1})
    expect_error(std::vector<uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(n)), "");
  expect_error({'n', 'o', 't', ' ', 'e', 'x', 'r'}, "");
  // A header attribute declaring 2 GB in a 30-byte file: refused before OpenEXR allocates it.
  std::vector<uint8_t> liar = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
  for (char ch : std::string("x\0string\0", 9)) liar.push_back(uint8_t(ch));
  for (int b : {0xff, 0xff, 0xff, 0x7f, int('a'), int('b')}) liar.push_back(uint8_t(b));
  expect_error(liar, "header attribute \"x\" claims 2147483647 bytes, more than the file holds");
  // A data window whose lines (or whose number of lines) OpenEXR would size its decode buffers
  // (offset table) by before reading a pixel: refused from the header (the exr_window fuzzer's
  // 688-byte file had OpenEXR allocate 2.1 GB).
  auto with_window_coordinate = [&good](int which, int32_t value) {
    std::vector<uint8_t> out = good;
    const std::string key("dataWindow\0box2i\0", 17);
    const auto at = std::search(out.begin(), out.end(), key.begin(), key.end());
    EXPECT_NE(at, out.end());
    const size_t value_at = size_t(at - out.begin()) + key.size() + 4 + 4 * size_t(which);
    for (int k = 0; k < 4; ++k) out[value_at + size_t(k)] = uint8_t(uint32_t(value) >> (8 * k));
    return out;
  };
  expect_error(with_window_coordinate(2, 1 << 29), "would take");              // max.x
  expect_error(with_window_coordinate(3, 1 << 29), "offset table is larger than the file");  // max.y
  // A scanline file is read as lines whatever attributes it carries: a "tiles" attribute (2^16 x 1
  // tiles) must not stand in for its lines' buffers (found by the fuzzer, 2.1 GB).
  auto with_tiles = [](std::vector<uint8_t> out, uint32_t flags_byte1) {
    std::vector<uint8_t> tiles;
    for (char ch : std::string("tiles\0tiledesc\0", 15)) tiles.push_back(uint8_t(ch));
    for (int b : {9, 0, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0}) tiles.push_back(uint8_t(b));
    out.insert(out.begin() + 8, tiles.begin(), tiles.end());
    out[5] = uint8_t(flags_byte1);
    return out;
  };
  expect_error(with_tiles(with_window_coordinate(2, 1 << 20), 0x00), "chunk of lines");
  // Without a "compression" attribute OpenEXR reads ZIP, 16 lines per chunk (the fuzzer's file
  // had its attribute's name altered): a 2^20-pixel-wide window, fine uncompressed line by line,
  // needs 16 lines' buffers.
  std::vector<uint8_t> unnamed = with_window_coordinate(2, 1 << 20);
  const std::string compression_key("compression\0compression\0", 24);
  const auto named = std::search(unnamed.begin(), unnamed.end(), compression_key.begin(), compression_key.end());
  ASSERT_NE(named, unnamed.end());
  named[1] = 'x';
  expect_error(unnamed, "chunk of lines");
  // A file flagged tiled is read as tiles, and needs their description.
  expect_error(with_tiles(good, 0x02), "");
  std::vector<uint8_t> untiled_flagged = good;
  untiled_flagged[5] |= 0x02;
  expect_error(untiled_flagged, "tiled file without a tile description");
  std::vector<uint8_t> deep = good;
  deep[5] |= 0x08;  // the deep-data flag of the version field
  expect_error(deep, "multi-part or deep");
  // Over the limit, judged from the header.
  ExrWindowLimits small;
  small.max_pixels = 69;
  expect_error(good, "over the limit of 69 pixels", small);
  // No beauty channels.
  const std::vector<float> z(20, 1.f);
  expect_error(encode_exr_channels({{"Z", z.data(), sizeof(float)}}, 5, 4, {}), "no beauty image");
  // A layer with some of its channels.
  const std::vector<float> rgb(60, 1.f);
  expect_error(encode_exr_channels({{"R", rgb.data(), 3 * sizeof(float)},
                                    {"G", rgb.data() + 1, 3 * sizeof(float)},
                                    {"B", rgb.data() + 2, 3 * sizeof(float)},
                                    {"normal.X", z.data(), sizeof(float)}},
                                   5, 4, {}),
               "layer normal lacks some of its channels");
  // Non-finite pixels are refused rather than merged into a frame.
  Image nan = window_image();
  nan.rgb[5] = NAN;
  const std::vector<float> raw = nan.rgb;
  expect_error(encode_exr_channels({{"R", raw.data(), 3 * sizeof(float)},
                                    {"G", raw.data() + 1, 3 * sizeof(float)},
                                    {"B", raw.data() + 2, 3 * sizeof(float)}},
                                   5, 4, {}),
               "non-finite");
  // A data window reaching outside the display window.
  const PixelWindow outside{7, 4, 12, 8};
  expect_error(encode_layered_exr(window_image(), {}, ExrLayout::kPlain, {}, &outside, &kFrame),
               "not inside the display window");
}

TEST(ExrWindowFile, AMissingFileIsAnErrorNamingIt) {
  EXPECT_THROW(read_exr_window("/nonexistent/part.exr"), ImageIoError);
}

}  // namespace
}  // namespace penumbra::test
