// One decoded copy per (file, colorspace) per scene, within the build's texture limits (the
// scene build's second line of defence behind api/'s header checks).
#include "renderer/textures/texture_image_cache.h"

#include <gtest/gtest.h>

#include "renderer/io/image_io.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

TEST(TextureImageCache, OneCopyPerFileAndColorspace) {
  TempFolder dir("texture_cache_share");
  const std::string png = dir.file("a.png");
  write_test_image(png, 4, 2, 3, std::vector<float>(24, 0.5f), OIIO::TypeDesc::UINT8);
  TextureImageCache cache;
  const TextureImage& first = cache.get(png, TextureColorspace::kSrgb);
  EXPECT_EQ(&cache.get(png, TextureColorspace::kSrgb), &first);
  const TextureImage& linear = cache.get(png, TextureColorspace::kLinear);
  EXPECT_NE(&linear, &first);
  EXPECT_EQ(cache.size(), 2u);
  EXPECT_EQ(cache.bytes(), 2 * 4 * 2 * 3);  // 8-bit images keep their bytes
}

TEST(TextureImageCache, TotalBytesAtTheLimitPassOneMoreFails) {
  TempFolder dir("texture_cache_limit");
  const std::string a = dir.file("a.exr"), b = dir.file("b.exr");
  write_test_image(a, 4, 4, 1, std::vector<float>(16, 1.f));  // 64 bytes decoded
  write_test_image(b, 2, 2, 1, std::vector<float>(4, 1.f));   // 16 bytes decoded
  TextureImageCache exact(TextureLimits{1 << 20, 80});
  EXPECT_NO_THROW(exact.get(a, TextureColorspace::kLinear));
  EXPECT_NO_THROW(exact.get(b, TextureColorspace::kLinear));
  EXPECT_EQ(exact.bytes(), 80);
  TextureImageCache short_by_one(TextureLimits{1 << 20, 79});
  EXPECT_NO_THROW(short_by_one.get(a, TextureColorspace::kLinear));
  EXPECT_THROW(short_by_one.get(b, TextureColorspace::kLinear), ImageIoError);
}

TEST(TextureImageCache, PixelLimitPerImage) {
  TempFolder dir("texture_cache_pixels");
  const std::string a = dir.file("a.exr");
  write_test_image(a, 4, 4, 1, std::vector<float>(16, 1.f));
  EXPECT_NO_THROW(TextureImageCache(TextureLimits{16, 1 << 20}).get(a, TextureColorspace::kLinear));
  EXPECT_THROW(TextureImageCache(TextureLimits{15, 1 << 20}).get(a, TextureColorspace::kLinear),
               ImageIoError);
}

}  // namespace
}  // namespace penumbra::test
