// PNG and EXR written by libpng and OpenEXR (renderer/io/png_writer, exr_writer), read back
// through the OpenImageIO plug-in: values, sRGB encoding, metadata, and the plug-in loaded only
// by the read.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <unistd.h>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"
#include "renderer/io/oiio_module.h"

namespace penumbra::test {
namespace {

Image gradient(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        img.rgb[3 * (size_t(y) * w + x) + c] = float(x + 2 * y + c) / float(w + 2 * h);
  return img;
}

std::string temp_path(const std::string& ext) {
  std::random_device rd;
  return (std::filesystem::temp_directory_path() /
          ("penumbra-codec-" + std::to_string(::getpid()) + "-" + std::to_string(rd()) + ext))
      .string();
}

// Encoding touches no OpenImageIO (ctest runs each test in its own process; run in one process
// with others, an earlier test may have loaded the plug-in, and this one is skipped).
TEST(ImageCodec, EncodingDoesNotLoadTheOpenImageIoPlugin) {
  if (oiio_module_loaded()) GTEST_SKIP() << "an earlier test of this process loaded the plug-in";
  const Image img = gradient(8, 4);
  EXPECT_GT(encode_image(img, ImageFormat::kPng).size(), 50u);
  EXPECT_GT(encode_image(img, ImageFormat::kExr).size(), 50u);
  EXPECT_FALSE(oiio_module_loaded());
}

TEST(ImageCodec, ExrRoundTripsFloatsExactly) {
  Image img = gradient(17, 9);
  img.rgb[5] = 1234.5f;   // HDR values survive
  img.rgb[7] = NAN;       // non-finite values are written as 0
  const std::string path = temp_path(".exr");
  write_image_file(path, img, {{"Software", "penumbra test"}});
  const Image back = read_image_file(path);
  ASSERT_EQ(back.width, 17);
  ASSERT_EQ(back.height, 9);
  for (size_t i = 0; i < img.rgb.size(); ++i)
    EXPECT_EQ(back.rgb[i], i == 7 ? 0.f : img.rgb[i]) << i;
  EXPECT_TRUE(oiio_module_loaded());
  std::remove(path.c_str());
}

TEST(ImageCodec, PngIsSrgbEncodedTo8Bits) {
  const Image img = gradient(16, 8);
  const std::string path = temp_path(".png");
  write_image_file(path, img);
  const AssetImage raw = read_asset_image(path);  // the stored 8-bit values, as floats
  ASSERT_EQ(raw.width, 16);
  ASSERT_EQ(raw.channels, 3);
  EXPECT_FALSE(raw.is_float);
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    const float v = img.rgb[i];
    const float srgb = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
    EXPECT_NEAR(raw.pixels[i], std::round(srgb * 255.f) / 255.f, 1e-6f) << i;
  }
  std::remove(path.c_str());
}

TEST(ImageCodec, UnsupportedExtensionIsAnError) {
  EXPECT_THROW(image_format_from_path("out.jpg"), ImageIoError);
}

}  // namespace
}  // namespace penumbra::test
