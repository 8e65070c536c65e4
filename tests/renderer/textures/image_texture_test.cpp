// Image texture lookups against values computed by hand: texel centres, bilinear weights,
// repeat and clamp at the border, nearest, the top-left origin, grey images and channels.
// Conventions: Mitsuba 3's `bitmap` (Dr.Jit texture_impl.h), restated in image_texture.h.
#include "renderer/textures/image_texture.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <vector>

namespace penumbra::test {
namespace {

// A 2 x 2 single-channel image, rows from the top:  a b
//                                                   c d
constexpr float a = 1.f, b = 2.f, c = 4.f, d = 8.f;
TextureImage grey2x2() { return TextureImage(2, 2, 1, {a, b, c, d}); }

float lookup(const TextureImage& img, vec2 uv, TextureWrap wrap = TextureWrap::kRepeat,
             TextureFilter filter = TextureFilter::kBilinear) {
  return ImageFloatTexture(img, 0, wrap, filter).eval(TextureQuery{vec3(0.f), uv, 0.f});
}

TEST(ImageTexture, TexelCentresGiveTheTexelItself) {
  // Centre of texel (x, y) is ((x + 0.5) / 2, (y + 0.5) / 2); (0, 0) is the top-left texel.
  const TextureImage img = grey2x2();
  EXPECT_FLOAT_EQ(lookup(img, {0.25f, 0.25f}), a);
  EXPECT_FLOAT_EQ(lookup(img, {0.75f, 0.25f}), b);
  EXPECT_FLOAT_EQ(lookup(img, {0.25f, 0.75f}), c);
  EXPECT_FLOAT_EQ(lookup(img, {0.75f, 0.75f}), d);
}

TEST(ImageTexture, BilinearWeightsByHand) {
  const TextureImage img = grey2x2();
  // The centre of the image: all four equally.
  EXPECT_FLOAT_EQ(lookup(img, {0.5f, 0.5f}), (a + b + c + d) / 4.f);
  // A quarter of the way from a's centre to b's: x = 0.375 -> p = 0.25.
  EXPECT_FLOAT_EQ(lookup(img, {0.375f, 0.25f}), 0.75f * a + 0.25f * b);
  // Between a and c, 3/4 of the way down: y = 0.625 -> p = 0.75.
  EXPECT_FLOAT_EQ(lookup(img, {0.25f, 0.625f}), 0.25f * a + 0.75f * c);
  // Off both axes: p = (0.25, 0.75).
  const float top = 0.75f * a + 0.25f * b, bottom = 0.75f * c + 0.25f * d;
  EXPECT_FLOAT_EQ(lookup(img, {0.375f, 0.625f}), 0.25f * top + 0.75f * bottom);
}

TEST(ImageTexture, RepeatBlendsWithTheOppositeEdgeAndClampWithItself) {
  const TextureImage img = grey2x2();
  // u = 0 lies half a texel left of a's centre: p = -0.5, between texel -1 (= 1 wrapped) and 0.
  EXPECT_FLOAT_EQ(lookup(img, {0.f, 0.25f}, TextureWrap::kRepeat), 0.5f * b + 0.5f * a);
  EXPECT_FLOAT_EQ(lookup(img, {0.f, 0.25f}, TextureWrap::kClamp), a);
  // Bottom-right corner: all four under repeat, d alone under clamp.
  EXPECT_FLOAT_EQ(lookup(img, {1.f, 1.f}, TextureWrap::kRepeat), (a + b + c + d) / 4.f);
  EXPECT_FLOAT_EQ(lookup(img, {1.f, 1.f}, TextureWrap::kClamp), d);
  // Far outside: repeat is periodic, clamp extends the border.
  EXPECT_FLOAT_EQ(lookup(img, {2.375f, -2.75f}, TextureWrap::kRepeat),
                  lookup(img, {0.375f, 0.25f}));
  EXPECT_FLOAT_EQ(lookup(img, {-3.f, 0.25f}, TextureWrap::kClamp), a);
  EXPECT_FLOAT_EQ(lookup(img, {5.f, 5.f}, TextureWrap::kClamp), d);
}

TEST(ImageTexture, NearestPicksTheTexelUnderUv) {
  const TextureImage img = grey2x2();
  const auto nearest = [&](vec2 uv, TextureWrap wrap = TextureWrap::kRepeat) {
    return lookup(img, uv, wrap, TextureFilter::kNearest);
  };
  EXPECT_EQ(nearest({0.01f, 0.01f}), a);
  EXPECT_EQ(nearest({0.49f, 0.01f}), a);
  EXPECT_EQ(nearest({0.5f, 0.01f}), b);   // texel 1 starts at u = 0.5
  EXPECT_EQ(nearest({0.01f, 0.99f}), c);  // v grows downwards
  EXPECT_EQ(nearest({1.f, 1.f}), a);      // repeat: u = 1 is texel 2 = texel 0
  EXPECT_EQ(nearest({1.f, 1.f}, TextureWrap::kClamp), d);
  EXPECT_EQ(nearest({-0.25f, 0.25f}), b);  // floor(-0.5) = -1 -> the last column
  EXPECT_EQ(nearest({-0.25f, 0.25f}, TextureWrap::kClamp), a);
}

TEST(ImageTexture, RgbAndGreyImagesAndChannels) {
  // 1 x 1 RGBA: the colour is RGB, alpha ignored; a float texture may read any channel.
  const TextureImage rgba(1, 1, 4, {0.1f, 0.2f, 0.3f, 0.4f});
  const TextureQuery q{vec3(0.f), vec2(0.3f, 0.6f), 0.f};
  constexpr TextureWrap kRep = TextureWrap::kRepeat;
  constexpr TextureFilter kNear = TextureFilter::kNearest;
  EXPECT_EQ(ImageSpectrumTexture(rgba, kRep, kNear).eval(q), Spectrum(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(ImageFloatTexture(rgba, 3, kRep, kNear).eval(q), 0.4f);
  EXPECT_EQ(ImageFloatTexture(rgba, 1, kRep, kNear).eval(q), 0.2f);
  // Grey and grey + alpha: the first channel in all three.
  const TextureImage ya(1, 1, 2, {0.6f, 0.9f});
  EXPECT_EQ(ImageSpectrumTexture(ya, kRep, kNear).eval(q), Spectrum(0.6f));
}

TEST(ImageTexture, ColourChannelsInterpolateIndependently) {
  // 2 x 1 RGB: red on the left, blue on the right; halfway between their centres: half each.
  const TextureImage img(2, 1, 3, {1.f, 0.f, 0.f, 0.f, 0.f, 1.f});
  const ImageSpectrumTexture t(img, TextureWrap::kClamp, TextureFilter::kBilinear);
  EXPECT_EQ(t.eval(TextureQuery{vec3(0.f), vec2(0.5f, 0.5f), 0.f}), Spectrum(0.5f, 0.f, 0.5f));
  EXPECT_EQ(t.mean(), Spectrum(0.5f, 0.f, 0.5f));
}

TEST(ImageTexture, NonFiniteOrHugeUvStaysInsideTheImage) {
  const TextureImage img = grey2x2();
  for (const vec2 uv :
       {vec2(NAN, 0.5f), vec2(INFINITY, -INFINITY), vec2(1e30f, -1e30f), vec2(3e9f, 0.f)}) {
    for (TextureWrap wrap : {TextureWrap::kRepeat, TextureWrap::kClamp})
      for (TextureFilter filter : {TextureFilter::kBilinear, TextureFilter::kNearest}) {
        const float v = lookup(img, uv, wrap, filter);
        EXPECT_TRUE(v >= a && v <= d) << uv.x << ", " << uv.y << " -> " << v;
      }
  }
}

// eval_many (the surface stages' lookups of many hits at once: coordinates and blend in SIMD
// lanes) gives eval's values to the bit: float and 8-bit sRGB images, RGB and grey, both filters
// and wraps, uv inside, on texel centres and edges, beyond the border, huge and non-finite, over
// more lanes than one chunk.
TEST(ImageTexture, EvalManyIsEvalToTheBit) {
  std::vector<float> floats;
  std::vector<uint8_t> bytes;
  for (int i = 0; i < 5 * 3 * 3; ++i) {
    floats.push_back(0.013f * float(i * i % 71) + 0.001f * float(i));
    bytes.push_back(uint8_t((i * 37 + 11) % 256));
  }
  const TextureImage images[] = {TextureImage(5, 3, 3, floats),
                                 TextureImage(5, 3, 3, bytes, TextureColorspace::kSrgb),
                                 TextureImage(5, 3, 1, {floats.begin(), floats.begin() + 15})};
  std::vector<float> u, v;
  for (int i = 0; i < 150; ++i) {  // more than one chunk of 64
    u.push_back(-1.3f + 0.0271f * float(i));
    v.push_back(0.9f - 0.0133f * float(i * 7 % 150));
  }
  for (const float x : {0.f, 0.1f, 0.5f, 1.f, 1.f / 3.f, -0.f, NAN, INFINITY, -INFINITY, 1e30f,
                        3e9f, -2.5e9f, 0.7f}) {
    u.push_back(x);
    v.push_back(0.5f);
    u.push_back(0.25f);
    v.push_back(x);
  }
  const size_t n = u.size();
  for (const TextureImage& image : images)
    for (TextureWrap wrap : {TextureWrap::kRepeat, TextureWrap::kClamp})
      for (TextureFilter filter : {TextureFilter::kBilinear, TextureFilter::kNearest}) {
        const ImageSpectrumTexture texture(image, wrap, filter);
        std::vector<float> r(n), g(n), b(n);
        texture.eval_many(n, u.data(), v.data(), r.data(), g.data(), b.data());
        const ImageFloatTexture last(image, image.channels() - 1, wrap, filter);
        std::vector<float> f(n);
        last.eval_many(n, u.data(), v.data(), f.data());
        for (size_t i = 0; i < n; ++i) {
          ASSERT_EQ(std::bit_cast<uint32_t>(f[i]),
                    std::bit_cast<uint32_t>(
                        last.eval(TextureQuery{vec3(0.f), vec2(u[i], v[i]), 0.f})))
              << "lane " << i << " uv " << u[i] << ", " << v[i];
          const Spectrum e = texture.eval(TextureQuery{vec3(0.f), vec2(u[i], v[i]), 0.f});
          ASSERT_EQ(std::bit_cast<uint32_t>(r[i]), std::bit_cast<uint32_t>(e.x))
              << "lane " << i << " uv " << u[i] << ", " << v[i];
          ASSERT_EQ(std::bit_cast<uint32_t>(g[i]), std::bit_cast<uint32_t>(e.y)) << "lane " << i;
          ASSERT_EQ(std::bit_cast<uint32_t>(b[i]), std::bit_cast<uint32_t>(e.z)) << "lane " << i;
        }
      }
}

}  // namespace
}  // namespace penumbra::test
