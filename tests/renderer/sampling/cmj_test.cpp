// Correlated multi-jittered points (renderer/sampling/cmj.h): each of a pixel's 2^k samples in
// its own cell of the coarse grid and its own fine row and column, the 1D value of a pair
// stratified with both coordinates, every sample uniform on its own (a render of fewer samples
// than the pattern takes a prefix), and the Sampler's values in CMJ mode these points.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "renderer/sampling/sampler.h"
#include "tests/renderer/sampling/chi2_util.h"

namespace penumbra::test {
namespace {

// The stratum of 2^bits a value in [0, 1) lies in (exact: the values are fixed point).
int stratum(float u, uint32_t bits) { return int(u * float(1u << bits)); }

TEST(Cmj, PermutationsArePermutations) {
  for (uint32_t k = 0; k <= 12; ++k)
    for (uint32_t p : {0u, 1u, 0x9e3779b9u, 0xdeadbeefu, 0xffffffffu}) {
      std::set<uint32_t> seen;
      for (uint32_t i = 0; i < (1u << k); ++i) {
        const uint32_t v = cmj_permute(i, (1u << k) - 1u, p);
        ASSERT_LT(v, 1u << k);
        seen.insert(v);
      }
      EXPECT_EQ(seen.size(), size_t(1u << k)) << "length 2^" << k << ", p " << p;
    }
}

TEST(Cmj, BitsForACountAreTheNextPowerOfTwo) {
  EXPECT_EQ(cmj_bits_for(1), 1u);
  EXPECT_EQ(cmj_bits_for(2), 1u);
  EXPECT_EQ(cmj_bits_for(3), 2u);
  EXPECT_EQ(cmj_bits_for(64), 6u);
  EXPECT_EQ(cmj_bits_for(65), 7u);
  EXPECT_EQ(cmj_bits_for(1u << 20), 20u);
  EXPECT_EQ(cmj_bits_for(1u << 24), 24u);
  EXPECT_EQ(cmj_bits_for((1u << 24) + 1), 0u);  // the Sobol sampler beyond
}

// A pixel's 2^bits samples of a dimension pair and of a 1D-2D pair, from the Sampler.
struct Points {
  std::vector<float> x, y, z;
};
Points sample_pixel(uint32_t bits, uint64_t seed, int px, int py, int dimension) {
  Points pts;
  Sampler s(seed, bits);
  for (uint32_t i = 0; i < (1u << bits); ++i) {
    s.start_pixel_sample(px, py, i);
    for (int d = 0; d < dimension; ++d) s.get_1d();
    float u1;
    vec2 u2;
    s.get_1d_2d(&u1, &u2);
    pts.x.push_back(u2.x);
    pts.y.push_back(u2.y);
    pts.z.push_back(u1);
  }
  return pts;
}

// One sample per cell of the m x n grid (m = 2^(bits/2) columns), per fine column and per fine
// row (N-rooks); the 1D value one per stratum of N, one per 1/n within each coarse column and
// one per 1/m within each coarse row.
TEST(Cmj, PointsAreStratifiedInEveryProjection) {
  for (uint32_t bits = 1; bits <= 10; ++bits) {
    const uint32_t a = bits / 2, c = bits - a, n_samples = 1u << bits;
    for (int trial = 0; trial < 4; ++trial) {
      const Points p = sample_pixel(bits, 7 + uint64_t(trial), 3 * trial, 5, trial);
      std::set<std::pair<int, int>> cells, xz, yz;
      std::set<int> fx, fy, fz;
      for (uint32_t i = 0; i < n_samples; ++i) {
        for (float u : {p.x[i], p.y[i], p.z[i]}) {
          ASSERT_GE(u, 0.f);
          ASSERT_LT(u, 1.f);
        }
        cells.insert({stratum(p.x[i], a), stratum(p.y[i], c)});
        fx.insert(stratum(p.x[i], bits));
        fy.insert(stratum(p.y[i], bits));
        fz.insert(stratum(p.z[i], bits));
        xz.insert({stratum(p.x[i], a), stratum(p.z[i], c)});
        yz.insert({stratum(p.y[i], c), stratum(p.z[i], a)});
      }
      const std::string what = "2^" + std::to_string(bits) + " samples, trial " + std::to_string(trial);
      EXPECT_EQ(cells.size(), n_samples) << what << ": coarse cells";
      EXPECT_EQ(fx.size(), n_samples) << what << ": fine columns";
      EXPECT_EQ(fy.size(), n_samples) << what << ": fine rows";
      EXPECT_EQ(fz.size(), n_samples) << what << ": the 1D value's strata";
      EXPECT_EQ(xz.size(), n_samples) << what << ": the 1D value with x";
      EXPECT_EQ(yz.size(), n_samples) << what << ": the 1D value with y";
    }
  }
}

// Every sample index is uniformly distributed over pixels (seeds): a render of spp samples takes
// the first spp of the next power of two, so no index may prefer a part of the square; and a
// pair's values are independent of another dimension's (the padding). Chi-square over 256-cell
// histograms across 40000 pixels: of (x, y, z) of a 1D-2D pair (8 x 8 x 4), and of the pair's
// (x, z) with dimension 0's 2D value (4 x 4 x 4 x 4).
TEST(Cmj, EachSampleIsUniformOnItsOwn) {
  for (uint32_t bits : {1u, 2u, 4u, 5u, 7u, 10u}) {
    const uint32_t n = 1u << bits;
    for (uint32_t index : {0u, 1u, n / 2, n - 1}) {
      std::vector<double> joint(256, 0.0), across(256, 0.0), expected(256, 40000.0 / 256.0);
      Sampler s(99, bits);
      for (int pixel = 0; pixel < 40000; ++pixel) {
        s.start_pixel_sample(pixel % 200, pixel / 200, index);
        const vec2 first = s.get_2d();
        float u1;
        vec2 u2;
        s.get_1d_2d(&u1, &u2);
        joint[size_t(stratum(u2.x, 3) * 32 + stratum(u2.y, 3) * 4 + stratum(u1, 2))] += 1.0;
        across[size_t(stratum(first.x, 2) * 64 + stratum(first.y, 2) * 16 + stratum(u2.x, 2) * 4 +
                      stratum(u1, 2))] += 1.0;
      }
      const std::string what = "2^" + std::to_string(bits) + " samples, index " + std::to_string(index);
      const Chi2Outcome r = chi2_goodness_of_fit(joint, expected, 1e-4);
      EXPECT_TRUE(r.pass) << what << ", a pair's three values: " << r.message;
      const Chi2Outcome c = chi2_goodness_of_fit(across, expected, 1e-4);
      EXPECT_TRUE(c.pass) << what << ", with dimension 0: " << c.message;
    }
  }
}

// The Sampler in CMJ mode: a 1D value is the x of its dimension's point, a pair's 2D value is
// get_2d's of its second dimension, and the values are those of cmj.h with the dimension's seeds.
TEST(Cmj, SamplerTakesThePointsOfItsDimensions) {
  constexpr uint32_t bits = 6;
  Sampler a(5, bits), b(5, bits);
  for (uint32_t i = 0; i < 64; i += 9) {
    a.start_pixel_sample(4, 2, i);
    b.start_pixel_sample(4, 2, i);
    const float one = a.get_1d();
    const vec2 two = b.get_2d();
    EXPECT_EQ(one, two.x);
    const DimensionScramble h = b.scramble(1);
    const uint32_t cell = cmj_cell(i, bits, h.index);
    const vec2 next = b.get_2d();
    EXPECT_EQ(next.x, fixed_to_unit_float(cmj_x(cell, bits, h.x)));
    EXPECT_EQ(next.y, fixed_to_unit_float(cmj_y(cell, bits, h.y)));
    float u1;
    vec2 u2;
    a.get_1d_2d(&u1, &u2);  // dimensions 1 and 2
    const DimensionScramble h2 = a.scramble(2);
    EXPECT_EQ(u2, b.get_2d());
    EXPECT_EQ(u1, fixed_to_unit_float(cmj_z(cmj_cell(i, bits, h2.index), bits, a.scramble(1).x)));
  }
}

}  // namespace
}  // namespace penumbra::test
