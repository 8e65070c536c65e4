// Decoding texture images: sRGB to linear at load (IEC 61966-2-1) for the colour channels only,
// linear kept as stored, and row 0 of the file at the top.
#include "renderer/textures/texture_image.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

// The sRGB decoding curve in double precision, written out from the standard.
double srgb_decode(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

TEST(TextureImage, EightBitSrgbIsDecodedAtLoadLinearIsNot) {
  TempFolder dir("texture_image_srgb");
  const std::string png = dir.file("rgb.png");
  // Code values 0, 10, 128, 255 in one row (10 is on the linear segment of the curve).
  write_test_image(png, 4, 1, 3,
                   {0.f, 0.f, 0.f, 10 / 255.f, 10 / 255.f, 10 / 255.f, 128 / 255.f, 128 / 255.f,
                    128 / 255.f, 1.f, 1.f, 1.f},
                   OIIO::TypeDesc::UINT8);
  const TextureImage srgb = load_texture_image(png, TextureColorspace::kSrgb);
  const TextureImage linear = load_texture_image(png, TextureColorspace::kLinear);
  const int codes[] = {0, 10, 128, 255};
  for (int x = 0; x < 4; ++x) {
    EXPECT_NEAR(srgb.value(x, 0, 0), srgb_decode(codes[x] / 255.0), 1e-6) << "code " << codes[x];
    EXPECT_NEAR(linear.value(x, 0, 1), codes[x] / 255.0, 1e-7) << "code " << codes[x];
  }
  EXPECT_NEAR(srgb.value(2, 0, 2), 0.2158605, 1e-6);  // the usual mid-grey: 128 -> 0.216
  // Kept as bytes: a quarter of the float memory.
  EXPECT_TRUE(srgb.is_8bit());
  EXPECT_EQ(srgb.bytes(), 4 * 1 * 3);
}

TEST(TextureImage, SixteenBitImagesAreDecodedToFloatsAtLoad) {
  TempFolder dir("texture_image_16bit");
  const std::string png = dir.file("grey16.png");
  write_test_image(png, 2, 1, 1, {0.5f, 1.f}, OIIO::TypeDesc::UINT16);
  const TextureImage img = load_texture_image(png, TextureColorspace::kSrgb);
  EXPECT_FALSE(img.is_8bit());
  EXPECT_EQ(img.bytes(), 2 * int64_t(sizeof(float)));
  EXPECT_NEAR(img.value(0, 0, 0), srgb_decode(32768 / 65535.0), 1e-6);
  EXPECT_NEAR(img.value(1, 0, 0), 1.0, 1e-7);
}

TEST(TextureImage, AlphaAndGreyAlphaKeepTheirAlphaLinear) {
  TempFolder dir("texture_image_alpha");
  const std::string rgba = dir.file("rgba.png"), ya = dir.file("ya.png");
  write_test_image(rgba, 1, 1, 4, {0.5f, 0.5f, 0.5f, 0.5f}, OIIO::TypeDesc::UINT8);
  write_test_image(ya, 1, 1, 2, {0.5f, 0.5f}, OIIO::TypeDesc::UINT8);
  const TextureImage a = load_texture_image(rgba, TextureColorspace::kSrgb);
  const TextureImage b = load_texture_image(ya, TextureColorspace::kSrgb);
  const double grey = srgb_decode(128 / 255.0), alpha = 128 / 255.0;
  EXPECT_NEAR(a.value(0, 0, 2), grey, 1e-6);
  EXPECT_NEAR(a.value(0, 0, 3), alpha, 1e-7);
  EXPECT_NEAR(b.value(0, 0, 0), grey, 1e-6);
  EXPECT_NEAR(b.value(0, 0, 1), alpha, 1e-7);  // a grey image's second channel is alpha
}

TEST(TextureImage, FloatImagesKeepTheirValuesAndRowZeroIsTheTop) {
  TempFolder dir("texture_image_exr");
  const std::string exr = dir.file("values.exr");
  write_test_image(exr, 2, 2, 1, {0.25f, 3.5f, -1.f, 100.f});  // HDR values survive as stored
  const TextureImage img = load_texture_image(exr, TextureColorspace::kLinear);
  ASSERT_EQ(img.width(), 2);
  ASSERT_EQ(img.channels(), 1);
  EXPECT_EQ(img.value(0, 0, 0), 0.25f);
  EXPECT_EQ(img.value(1, 0, 0), 3.5f);
  EXPECT_EQ(img.value(0, 1, 0), -1.f);
  EXPECT_EQ(img.value(1, 1, 0), 100.f);
  EXPECT_FLOAT_EQ(img.mean(0), (0.25f + 3.5f - 1.f + 100.f) / 4.f);
}

}  // namespace
}  // namespace penumbra::test
