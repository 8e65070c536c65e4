// PNG assets decoded by libpng (renderer/io/png_reader.h) against OpenImageIO's reader through the
// plug-in, which decoded them before: the same channels and the same floats for every colour type,
// bit depth, palette, transparency chunk and interlacing, except that colour is not multiplied by
// alpha; from a file and from memory; the plug-in not loaded by PNG files.
#include "renderer/io/png_reader.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
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

// One kind of PNG file: libpng's colour type, bit depth, and optional chunks.
struct PngKind {
  const char* name;
  int color_type;
  int bit_depth;
  bool trns = false;      // a tRNS chunk (palette alphas, or one transparent grey/RGB value)
  bool interlaced = false;
};

int stored_channels(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY: return 1;
    case PNG_COLOR_TYPE_GRAY_ALPHA: return 2;
    case PNG_COLOR_TYPE_RGB: return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA: return 4;
    default: return 1;  // palette indices
  }
}

// The i-th stored sample (row-major over rows of channels): a multiplicative hash of i.
uint32_t sample(const PngKind& kind, int i) {
  return (uint32_t(i) * 2654435761u >> 7) % (uint32_t(1) << kind.bit_depth);
}

// Writes a `w` x `h` PNG of the given kind whose samples run through every value the depth holds
// (a multiplicative hash of the position), so each value's conversion is compared.
void write_png(const std::string& path, const PngKind& kind, int w, int h) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  ASSERT_EQ(setjmp(png_jmpbuf(png)), 0);
  png_init_io(png, f);
  png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), kind.bit_depth, kind.color_type,
               kind.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  const int max = (1 << kind.bit_depth) - 1;
  std::vector<png_color> palette;
  std::vector<png_byte> alphas;
  png_color_16 transparent{};
  if (kind.color_type == PNG_COLOR_TYPE_PALETTE) {
    for (int i = 0; i <= max; ++i)
      palette.push_back({png_byte(37 * i + 11), png_byte(255 - 13 * i), png_byte(91 * i)});
    png_set_PLTE(png, info, palette.data(), int(palette.size()));
    if (kind.trns) {
      for (int i = 0; i <= max; ++i) alphas.push_back(png_byte(i % 3 == 0 ? 255 : 29 * i));
      png_set_tRNS(png, info, alphas.data(), int(alphas.size()), nullptr);
    }
  } else if (kind.trns) {
    // The first pixel's value is the transparent one, so at least one pixel is transparent.
    transparent.gray = png_uint_16(sample(kind, 0));
    transparent.red = png_uint_16(sample(kind, 0));
    transparent.green = png_uint_16(sample(kind, 1));
    transparent.blue = png_uint_16(sample(kind, 2));
    png_set_tRNS(png, info, nullptr, 0, &transparent);
  }
  png_write_info(png, info);
  if (kind.bit_depth == 16) png_set_swap(png);  // rows below hold host-order uint16
  if (kind.bit_depth < 8) png_set_packing(png);  // one sample per byte below
  const int channels = stored_channels(kind.color_type);
  const size_t sample_bytes = kind.bit_depth == 16 ? 2 : 1;
  std::vector<std::vector<png_byte>> rows(size_t(h), std::vector<png_byte>(size_t(w * channels) * sample_bytes));
  for (int y = 0; y < h; ++y)
    for (int i = 0; i < w * channels; ++i) {
      const uint32_t v = sample(kind, y * w * channels + i);
      if (sample_bytes == 2) {
        const uint16_t s = uint16_t(v);
        std::memcpy(&rows[size_t(y)][size_t(2 * i)], &s, 2);
      } else {
        rows[size_t(y)][size_t(i)] = png_byte(v);
      }
    }
  std::vector<png_bytep> pointers;
  for (auto& r : rows) pointers.push_back(r.data());
  png_write_image(png, pointers.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

const PngKind kKinds[] = {
    {"rgb8", PNG_COLOR_TYPE_RGB, 8},
    {"rgba8", PNG_COLOR_TYPE_RGB_ALPHA, 8},
    {"grey8", PNG_COLOR_TYPE_GRAY, 8},
    {"grey_alpha8", PNG_COLOR_TYPE_GRAY_ALPHA, 8},
    {"grey1", PNG_COLOR_TYPE_GRAY, 1},
    {"grey2", PNG_COLOR_TYPE_GRAY, 2},
    {"grey4", PNG_COLOR_TYPE_GRAY, 4},
    {"palette8", PNG_COLOR_TYPE_PALETTE, 8},
    {"palette4_trns", PNG_COLOR_TYPE_PALETTE, 4, true},
    {"palette2", PNG_COLOR_TYPE_PALETTE, 2},
    {"grey8_trns", PNG_COLOR_TYPE_GRAY, 8, true},
    {"rgb8_trns", PNG_COLOR_TYPE_RGB, 8, true},
    {"rgb16", PNG_COLOR_TYPE_RGB, 16},
    {"rgba16", PNG_COLOR_TYPE_RGB_ALPHA, 16},
    {"grey16", PNG_COLOR_TYPE_GRAY, 16},
    {"rgb8_interlaced", PNG_COLOR_TYPE_RGB, 8, false, true},
    {"grey_alpha16_interlaced", PNG_COLOR_TYPE_GRAY_ALPHA, 16, false, true},
};

// OpenImageIO (through the plug-in) as the reference decoder of a file: header and floats.
struct PluginDecoded {
  PenumbraImageSpec spec;
  std::vector<float> pixels;
};
PluginDecoded decode_with_plugin(const std::string& path) {
  auto image = open_plugin_image(path);
  PluginDecoded out{image->spec(), {}};
  out.pixels.resize(size_t(out.spec.width) * size_t(out.spec.height) * size_t(out.spec.channels));
  image->read(out.spec.channels, out.pixels.data());
  return out;
}

TEST(PngReader, PngFilesDoNotLoadTheOpenImageIoPlugin) {
  if (oiio_module_loaded()) GTEST_SKIP() << "an earlier test of this process loaded the plug-in";
  // ctest runs each test in its own process; in one process with others it may be skipped.
  TempFolder dir("png_no_plugin");
  const std::string path = dir.file("a.png");
  write_png(path, kKinds[0], 7, 5);
  EXPECT_EQ(probe_asset_image(path).width, 7);
  EXPECT_EQ(read_asset_image(path).pixels.size(), 7u * 5u * 3u);
  EXPECT_EQ(read_asset_image_8bit(path).pixels.size(), 7u * 5u * 3u);
  EXPECT_FALSE(oiio_module_loaded());
}

TEST(PngReader, DecodesEveryKindAsOpenImageIoDoesBitForBit) {
  TempFolder dir("png_kinds");
  for (const PngKind& kind : kKinds) {
    SCOPED_TRACE(kind.name);
    const std::string path = dir.file(std::string(kind.name) + ".png");
    const int w = 37, h = 23;  // odd sizes: every Adam7 pass, partial bytes of packed rows
    write_png(path, kind, w, h);
    const PluginDecoded ref = decode_with_plugin(path);
    const AssetImageInfo info = probe_asset_image(path);
    ASSERT_EQ(info.width, ref.spec.width);
    ASSERT_EQ(info.height, ref.spec.height);
    ASSERT_EQ(info.channels, ref.spec.channels);
    EXPECT_EQ(info.is_8bit, ref.spec.is_uint8 != 0);
    EXPECT_FALSE(info.is_float);
    const AssetImage ours = read_asset_image(path);
    ASSERT_EQ(ours.pixels.size(), ref.pixels.size());
    const int channels = info.channels;
    const bool has_alpha = channels == 2 || channels == 4;
    int mismatches = 0, translucent = 0;
    for (size_t p = 0; p < ref.pixels.size() / size_t(channels); ++p) {
      const float alpha = has_alpha ? ours.pixels[(p + 1) * size_t(channels) - 1] : 1.f;
      for (int c = 0; c < channels; ++c) {
        const size_t i = p * size_t(channels) + size_t(c);
        const bool colour_of_translucent = has_alpha && c < channels - 1 && alpha < 1.f;
        if (!colour_of_translucent) {
          mismatches += ours.pixels[i] != ref.pixels[i];
          continue;
        }
        // OpenImageIO multiplies colour by alpha; the stored (unassociated) value is ours.
        ++translucent;
        EXPECT_NEAR(ours.pixels[i] * alpha, ref.pixels[i], 1.5f / 255.f) << i;
      }
    }
    EXPECT_EQ(mismatches, 0);
    if (kind.trns || kind.color_type & PNG_COLOR_MASK_ALPHA) EXPECT_GT(translucent, 0);
    // Every value the depth holds was compared (the hash covers them).
    if (info.is_8bit) {
      const AssetImage8 raw = read_asset_image_8bit(path);
      ASSERT_EQ(raw.pixels.size(), ours.pixels.size());
      for (size_t i = 0; i < raw.pixels.size(); ++i)
        ASSERT_EQ(float(raw.pixels[i]) * (1.f / 255.f), ours.pixels[i]) << i;
    } else {
      EXPECT_THROW(read_asset_image_8bit(path), ImageIoError);
    }
  }
}

TEST(PngReader, ImageInMemoryDecodesAsItsFile) {
  TempFolder dir("png_memory");
  const std::string path = dir.file("m.png");
  write_png(path, kKinds[1], 19, 11);
  const std::string bytes = file_bytes(path);
  const ImageSource source("embedded image 3",
                           std::make_shared<const std::vector<uint8_t>>(bytes.begin(), bytes.end()), "png");
  const AssetImage from_memory = read_asset_image(source), from_file = read_asset_image(path);
  EXPECT_EQ(from_memory.pixels, from_file.pixels);
  EXPECT_EQ(from_memory.channels, 4);
}

TEST(PngReader, BrokenFilesFailWithTheSourceNamed) {
  TempFolder dir("png_broken");
  const std::string path = dir.file("whole.png");
  write_png(path, kKinds[0], 64, 64);
  const std::string bytes = file_bytes(path);
  // Cut anywhere after the signature: the header or the rows end early.
  for (size_t cut : {size_t(9), size_t(20), size_t(40), bytes.size() / 2, bytes.size() - 13}) {
    SCOPED_TRACE(cut);
    const std::string name = dir.file("cut" + std::to_string(cut) + ".png");
    std::ofstream(name, std::ios::binary) << bytes.substr(0, cut);
    expect_refused_naming([&] { read_asset_image(name); }, name, "cannot");
    auto memory = std::make_shared<const std::vector<uint8_t>>(bytes.begin(), bytes.begin() + std::ptrdiff_t(cut));
    expect_refused_naming([&] { read_asset_image(ImageSource("embedded", memory, "png")); }, "embedded", "cannot");
  }
  // A flipped bit in the image data: the chunk's CRC no longer matches.
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = char(flipped[bytes.size() / 2] ^ 0x10);
  const std::string bad = dir.file("flipped.png");
  std::ofstream(bad, std::ios::binary) << flipped;
  expect_refused_naming([&] { read_asset_image(bad); }, bad, "cannot decode the image");
}

}  // namespace
}  // namespace penumbra::test
