// OpenEXR's thread pool (renderer/io/exr_threads.h): the files penumbra writes are the same bytes
// and the files it reads the same floats whether their chunks are compressed and decompressed on
// the caller's thread or on the pool.
#include "renderer/io/exr_threads.h"

#include <OpenEXR/ImfThreading.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"
#include "renderer/io/layer_io.h"

namespace penumbra::test {
namespace {

// Many chunks (ZIP packs 16 lines), a last one shorter, values no pattern compresses away.
Image test_image(int w, int h) {
  Image image(w, h);
  for (size_t i = 0; i < image.rgb.size(); ++i)
    image.rgb[i] = float((i * 2654435761u) % 100003u) / 1000.f;
  return image;
}

struct PoolSize {  // restores the pool's size after a test
  int before = exr_threads();
  ~PoolSize() { set_exr_threads(before); }
};

TEST(ExrThreads, ThePoolIsSizedOnFirstUse) {
  const int n = exr_threads();
  EXPECT_GE(n, 1);
  EXPECT_LE(n, kMaxExrThreads);
  EXPECT_EQ(Imf::globalThreadCount(), n);
}

TEST(ExrThreads, WrittenFilesAreTheSameBytesOnAnyNumberOfThreads) {
  PoolSize restore;
  const Image image = test_image(257, 131);
  ImageLayer depth{"depth", ImageLayer::Kind::kDepth, 1, std::vector<float>(257 * 131)};
  for (size_t i = 0; i < depth.data.size(); ++i) depth.data[i] = float(i % 977) * 0.25f;
  const std::vector<ImageLayer> layers = {depth};
  const ImageMetadata meta = {{"penumbra:spp", "4"}};
  set_exr_threads(0);
  const auto one = encode_image(image, ImageFormat::kExr, meta);
  const auto layered_one = encode_layered_exr(image, layers, ExrLayout::kPlain, meta);
  for (int threads : {1, 2, 4, 7}) {
    set_exr_threads(threads);
    EXPECT_EQ(encode_image(image, ImageFormat::kExr, meta), one) << threads << " threads";
    EXPECT_EQ(encode_layered_exr(image, layers, ExrLayout::kPlain, meta), layered_one)
        << threads << " threads";
  }
}

TEST(ExrThreads, ReadFilesAreTheSameFloatsOnAnyNumberOfThreads) {
  PoolSize restore;
  const Image image = test_image(300, 77);
  const auto bytes = std::make_shared<const std::vector<uint8_t>>(
      encode_image(image, ImageFormat::kExr, {}));
  const ImageSource source("embedded image", bytes, "exr");
  set_exr_threads(0);
  const auto serial = read_asset_image(source);
  ASSERT_EQ(serial.width, 300);
  ASSERT_EQ(serial.height, 77);
  ASSERT_EQ(serial.channels, 3);
  ASSERT_EQ(serial.pixels, image.rgb);  // float EXR: exact
  for (int threads : {2, 5}) {
    set_exr_threads(threads);
    EXPECT_EQ(read_asset_image(source).pixels, serial.pixels) << threads << " threads";
  }
  // A file cut short fails on the pool as on one thread, with the source named.
  const auto cut = std::make_shared<const std::vector<uint8_t>>(bytes->begin(),
                                                                bytes->begin() + bytes->size() / 2);
  set_exr_threads(4);
  try {
    read_asset_image(ImageSource("cut image", cut, "exr"));
    FAIL() << "a truncated EXR was read";
  } catch (const ImageIoError& e) {
    EXPECT_NE(std::string(e.what()).find("cut image"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra::test
