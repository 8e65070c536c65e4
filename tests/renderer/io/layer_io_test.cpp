// Output layers encoded as multi-layer EXR (plain and Blender channel names) and as one file per
// layer, read back with OpenImageIO: channel names, values, and the PNG encodings of
// docs/output-layers.md.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "renderer/io/layer_io.h"
#include "renderer/render/output_layers.h"

namespace penumbra::test {
namespace {

constexpr int kW = 5, kH = 3;

Image beauty() {
  Image img(kW, kH);
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = 0.1f * float(i % 7);
  return img;
}

std::vector<ImageLayer> layers() {
  ImageLayer albedo{"albedo", ImageLayer::Kind::kColor, 3, std::vector<float>(kW * kH * 3)};
  ImageLayer normal{"normal", ImageLayer::Kind::kVector, 3, std::vector<float>(kW * kH * 3)};
  ImageLayer depth{"depth", ImageLayer::Kind::kDepth, 1, std::vector<float>(kW * kH)};
  for (int i = 0; i < kW * kH; ++i) {
    albedo.data[3 * i] = 0.25f;
    albedo.data[3 * i + 1] = 0.5f;
    albedo.data[3 * i + 2] = 1.f;
    normal.data[3 * i] = -1.f;
    normal.data[3 * i + 1] = 0.f;
    normal.data[3 * i + 2] = 1.f;
    depth.data[i] = 2.f + float(i);
  }
  depth.data[kW * kH - 1] = kBackgroundDepth;
  return {albedo, normal, depth};
}

struct Decoded {
  std::vector<std::string> channels;
  std::vector<float> pixels;
  std::string blender_attribute;
  int width = 0, height = 0;
  float value(int pixel, const std::string& channel) const {
    const auto it = std::find(channels.begin(), channels.end(), channel);
    if (it == channels.end()) return NAN;
    return pixels[size_t(pixel) * channels.size() + size_t(it - channels.begin())];
  }
};

// Through a file, as a user's tool would read it.
Decoded decode(const std::vector<uint8_t>& bytes, const std::string& ext) {
  std::random_device rd;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("penumbra-layer-io-" + std::to_string(::getpid()) + "-" +
                             std::to_string(rd()) + "." + ext))
                               .string();
  write_file_atomically(path, bytes);
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << OIIO::geterror();
  Decoded d;
  if (!in) {
    std::filesystem::remove(path);
    return d;
  }
  const OIIO::ImageSpec& spec = in->spec();
  d.channels = spec.channelnames;
  d.width = spec.width;
  d.height = spec.height;
  d.blender_attribute = spec.get_string_attribute("BlenderMultiChannel");
  d.pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, d.pixels.data()));
  in->close();
  std::filesystem::remove(path);
  return d;
}

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

TEST(LayerIo, PlainLayoutNamesAndValues) {
  const Decoded d = decode(encode_layered_exr(beauty(), layers(), ExrLayout::kPlain), "exr");
  EXPECT_EQ(sorted(d.channels),
            sorted({"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y",
                    "normal.Z", "depth.Z"}));
  EXPECT_EQ(d.width, kW);
  EXPECT_FLOAT_EQ(d.value(4, "G"), beauty().rgb[13]);
  EXPECT_FLOAT_EQ(d.value(4, "albedo.G"), 0.5f);
  EXPECT_FLOAT_EQ(d.value(4, "normal.X"), -1.f);
  EXPECT_FLOAT_EQ(d.value(4, "depth.Z"), 6.f);
  EXPECT_FLOAT_EQ(d.value(kW * kH - 1, "depth.Z"), kBackgroundDepth);
  EXPECT_TRUE(d.blender_attribute.empty());
}

TEST(LayerIo, BlenderLayoutNamesAndAlpha) {
  const Decoded d = decode(encode_layered_exr(beauty(), layers(), ExrLayout::kBlender), "exr");
  EXPECT_EQ(sorted(d.channels),
            sorted({"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
                    "ViewLayer.Combined.A", "ViewLayer.Denoising Albedo.R",
                    "ViewLayer.Denoising Albedo.G", "ViewLayer.Denoising Albedo.B",
                    "ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z",
                    "ViewLayer.Depth.Z"}));
  EXPECT_FLOAT_EQ(d.value(7, "ViewLayer.Combined.A"), 1.f);
  EXPECT_FLOAT_EQ(d.value(7, "ViewLayer.Combined.R"), beauty().rgb[21]);
  EXPECT_FLOAT_EQ(d.value(7, "ViewLayer.Depth.Z"), 9.f);
  EXPECT_FALSE(d.blender_attribute.empty());
  // Without layers: the Combined pass alone, still in Blender's layout.
  const Decoded c = decode(encode_layered_exr(beauty(), {}, ExrLayout::kBlender), "exr");
  EXPECT_EQ(c.channels.size(), 4u);
}

TEST(LayerIo, NonFiniteValuesAreWrittenAsZero) {
  std::vector<ImageLayer> l = layers();
  l[0].data[0] = NAN;
  l[2].data[1] = INFINITY;
  const Decoded d = decode(encode_layered_exr(beauty(), l, ExrLayout::kPlain), "exr");
  EXPECT_EQ(d.value(0, "albedo.R"), 0.f);
  EXPECT_EQ(d.value(1, "depth.Z"), 0.f);
}

TEST(LayerIo, SeparateFiles) {
  const std::vector<ImageLayer> l = layers();
  Decoded d = decode(encode_layer(l[2], kW, kH, ImageFormat::kExr), "exr");
  EXPECT_EQ(d.channels, std::vector<std::string>{"Z"});
  EXPECT_FLOAT_EQ(d.value(3, "Z"), 5.f);
  d = decode(encode_layer(l[1], kW, kH, ImageFormat::kExr), "exr");
  EXPECT_EQ(sorted(d.channels), sorted({"X", "Y", "Z"}));
  // PNG: a normal n as n * 0.5 + 0.5 (bytes 0, 128, 255), not sRGB-encoded.
  d = decode(encode_layer(l[1], kW, kH, ImageFormat::kPng), "png");
  ASSERT_EQ(d.channels.size(), 3u);
  EXPECT_FLOAT_EQ(d.pixels[0] * 255.f, 0.f);
  EXPECT_FLOAT_EQ(d.pixels[1] * 255.f, 128.f);
  EXPECT_FLOAT_EQ(d.pixels[2] * 255.f, 255.f);
  // Depth: near (2) black, far (15) white, the background white.
  d = decode(encode_layer(l[2], kW, kH, ImageFormat::kPng), "png");
  EXPECT_FLOAT_EQ(d.pixels[0], 0.f);
  EXPECT_NEAR(d.pixels[3 * 13], 1.f, 1e-6f);
  EXPECT_NEAR(d.pixels[3 * 6], std::round(6.f / 13.f * 255.f) / 255.f, 1e-6f);  // depth 8
  EXPECT_NEAR(d.pixels[3 * 14], 1.f, 1e-6f);
  // Albedo: sRGB-encoded like the beauty image (0.5 linear -> 188).
  d = decode(encode_layer(l[0], kW, kH, ImageFormat::kPng), "png");
  EXPECT_FLOAT_EQ(d.pixels[1] * 255.f, 188.f);
}

TEST(LayerIo, LayerFilePaths) {
  EXPECT_EQ(layer_file_path("out.png", "albedo"), "out.albedo.png");
  EXPECT_EQ(layer_file_path("dir.v2/out.exr", "depth"), "dir.v2/out.depth.exr");
  EXPECT_EQ(layer_file_path("dir.v2/out", "normal"), "dir.v2/out.normal");
}

}  // namespace
}  // namespace penumbra::test
