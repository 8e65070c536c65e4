// The Owen-scrambled Sobol sampler: values in [0,1), stratified like a (0,m,2)-net in every
// dimension pair, independent between pixels and dimensions.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <tuple>

#include "renderer/sampling/sampler.h"

namespace penumbra::test {
namespace {

TEST(Sampler, ValuesAreInUnitInterval) {
  Sampler s(3);
  for (int i = 0; i < 4096; ++i) {
    s.start_pixel_sample(i % 7, i % 5, uint32_t(i));
    for (int d = 0; d < 8; ++d) {
      const float a = s.get_1d();
      const vec2 b = s.get_2d();
      ASSERT_GE(a, 0.f);
      ASSERT_LT(a, 1.f);
      ASSERT_GE(b.x, 0.f);
      ASSERT_LT(b.x, 1.f);
      ASSERT_GE(b.y, 0.f);
      ASSERT_LT(b.y, 1.f);
    }
  }
}

// The first 2^m samples of a 2D dimension fall one per elementary interval of every shape
// 2^-k x 2^-(m-k): the property that makes it beat independent random numbers.
TEST(Sampler, TwoDimensionalSamplesFormANet) {
  constexpr int m = 8, n = 1 << m;
  for (int dim_pair = 0; dim_pair < 4; ++dim_pair) {
    std::vector<vec2> pts;
    Sampler s(11);
    for (int i = 0; i < n; ++i) {
      s.start_pixel_sample(5, 9, uint32_t(i));
      vec2 p;
      for (int d = 0; d <= dim_pair; ++d) p = s.get_2d();
      pts.push_back(p);
    }
    for (int k = 0; k <= m; ++k) {
      std::set<std::pair<int, int>> cells;
      for (const vec2& p : pts) cells.insert({int(p.x * (1 << k)), int(p.y * (1 << (m - k)))});
      EXPECT_EQ(int(cells.size()), n) << "dimension pair " << dim_pair << ", k " << k;
    }
  }
}

// get_1d_2d: the 2D value is get_2d's of the second dimension, and with the 1D value the first
// 2^m samples form a (1, m, 3)-net (Sobol's first three dimensions): every elementary box of
// volume 2^-(m-1) holds exactly two of them, so the 1D value is stratified with the 2D one, not
// only beside it.
TEST(Sampler, OneAndTwoDimensionalPairIsA3DNet) {
  constexpr int m = 8, n = 1 << m;
  for (int first = 0; first < 3; ++first) {
    std::vector<vec3> pts;
    Sampler s(17), plain(17);
    for (int i = 0; i < n; ++i) {
      s.start_pixel_sample(2, 7, uint32_t(i));
      plain.start_pixel_sample(2, 7, uint32_t(i));
      for (int d = 0; d < 2 * first; ++d) s.get_1d(), plain.get_1d();
      float u1;
      vec2 u2;
      s.get_1d_2d(&u1, &u2);
      plain.get_1d();
      const vec2 p2 = plain.get_2d();
      ASSERT_EQ(u2.x, p2.x);
      ASSERT_EQ(u2.y, p2.y);
      ASSERT_EQ(s.cursor().dimension, plain.cursor().dimension);
      ASSERT_GE(u1, 0.f);
      ASSERT_LT(u1, 1.f);
      pts.push_back(vec3(u1, u2.x, u2.y));
    }
    for (int a = 0; a <= m - 1; ++a)
      for (int b = 0; a + b <= m - 1; ++b) {
        const int c = m - 1 - a - b;
        std::map<std::tuple<int, int, int>, int> boxes;
        for (const vec3& p : pts) ++boxes[{int(p.x * (1 << a)), int(p.y * (1 << b)), int(p.z * (1 << c))}];
        EXPECT_EQ(int(boxes.size()), n / 2) << "pair " << first << ", box " << a << " " << b << " " << c;
        for (const auto& [box, count] : boxes) ASSERT_EQ(count, 2);
      }
  }
}

TEST(Sampler, OneDimensionalSamplesAreStratified) {
  constexpr int n = 64;
  Sampler s(5);
  std::set<int> strata;
  for (int i = 0; i < n; ++i) {
    s.start_pixel_sample(1, 2, uint32_t(i));
    strata.insert(int(s.get_1d() * n));
  }
  EXPECT_EQ(int(strata.size()), n);
}

TEST(Sampler, PixelsAndDimensionsAreDecorrelated) {
  Sampler s(0);
  s.start_pixel_sample(0, 0, 0);
  const vec2 a = s.get_2d(), b = s.get_2d();
  s.start_pixel_sample(1, 0, 0);
  const vec2 c = s.get_2d();
  EXPECT_NE(a, b);
  EXPECT_NE(a, c);
  // Mean of many pixels' first sample is 1/2 (scrambles are uniform).
  double sum = 0.0;
  for (int x = 0; x < 4096; ++x) {
    s.start_pixel_sample(x, 3, 0);
    sum += s.get_1d();
  }
  EXPECT_NEAR(sum / 4096.0, 0.5, 0.015);
}

}  // namespace
}  // namespace penumbra::test

namespace penumbra::test {
namespace {
TEST(Sampler, ClosedFormSobolDimension1MatchesBitLoop) {
  uint32_t x = 12345;
  for (int i = 0; i < 100000; ++i) {
    x = x * 1664525u + 1013904223u;
    ASSERT_EQ(sobol_dimension1(x), sobol_dimension1_reference(x)) << x;
  }
  EXPECT_EQ(nested_uniform_scramble(sobol_dimension0(77u), 991u),
            reverse_bits32(laine_karras_permutation(77u, 991u)));
}

// The compile-time keys of the cached dimensions are hash_combine's hash of the dimension, so
// cached dimensions get the seeds the uncached ones (64 and up) get from hash_combine itself.
TEST(Sampler, DimensionKeysAreHashCombines) {
  for (uint64_t seed : {0ull, 1ull, 0x0123456789abcdefull})
    for (uint64_t d = 0; d < SamplerDimensionKeys::kCount; ++d)
      ASSERT_EQ(mix64(seed ^ kSamplerDimensionKeys.key[d]), hash_combine(seed, d)) << d;
}
}  // namespace
}  // namespace penumbra::test
