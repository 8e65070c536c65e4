// Adaptive sampling's allocation (renderer/adaptive_sampling.h): samples in proportion to each
// pixel's relative deviation (Neyman allocation), scaled so the image's relMSE is threshold^2.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "renderer/render/adaptive_sampling.h"

namespace penumbra::test {
namespace {

constexpr int kW = 64, kH = 64;

// relMSE the allocation gives when pixel i has deviation s_i: mean of s_i^2 / n_i.
double predicted_relmse(const std::vector<double>& s, const std::vector<uint32_t>& n) {
  double sum = 0.0;
  for (size_t i = 0; i < s.size(); ++i) sum += s[i] * s[i] / n[i];
  return sum / double(s.size());
}

double mean_samples(const std::vector<uint32_t>& n) {
  return std::accumulate(n.begin(), n.end(), 0.0) / double(n.size());
}

// Left half of the image four times as noisy per sample as the right half.
std::vector<double> two_regions(double left, double right) {
  std::vector<double> s(size_t(kW) * kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) s[size_t(y) * kW + x] = x < kW / 2 ? left : right;
  return s;
}

TEST(AdaptiveSampleLimits, EvenNoiseGivesEveryPixelWhatTheThresholdNeeds) {
  const std::vector<double> s(size_t(kW) * kH, 2.0);
  const auto n = adaptive_sample_limits(s, kW, kH, {0.1f, 16, 100000});
  for (uint32_t v : n) ASSERT_EQ(v, 400u);  // s^2 / t^2
  EXPECT_NEAR(predicted_relmse(s, n), 0.01, 1e-6);
}

TEST(AdaptiveSampleLimits, SamplesAreProportionalToDeviationNotItsSquare) {
  const std::vector<double> s = two_regions(4.0, 1.0);
  const auto n = adaptive_sample_limits(s, kW, kH, {0.05f, 16, 1000000});
  // Away from the boundary columns (the 3x3 neighbourhood mixes the two there).
  const double noisy = n[size_t(10) * kW + 5], quiet = n[size_t(10) * kW + kW - 5];
  EXPECT_NEAR(noisy / quiet, 4.0, 0.01);  // an equal-error rule would give 16
  // The threshold is the image's relative RMS error (the boundary columns, judged by neighbours
  // from both sides, are a little off, and the scale makes up for them).
  const double relmse = predicted_relmse(s, n);
  EXPECT_LE(relmse, 1.001 * 0.05 * 0.05);  // (each pixel's own term left out of its scale)
  EXPECT_GE(relmse, 0.95 * 0.05 * 0.05);
}

// The point of the allocation: for the samples it spends, its relMSE is (mean s)^2 / mean(n)
// (Cauchy-Schwarz bound), below uniform sampling's mean(s^2) / mean(n) and below the per-pixel
// equal-error rule (which ties with uniform).
TEST(AdaptiveSampleLimits, ReachesTheOptimalErrorForItsSampleCount) {
  const std::vector<double> s = two_regions(4.0, 1.0);
  const auto n = adaptive_sample_limits(s, kW, kH, {0.05f, 16, 1000000});
  const double cost = predicted_relmse(s, n) * mean_samples(n);
  const double optimal = 2.5 * 2.5, uniform = (16.0 + 1.0) / 2.0;
  EXPECT_NEAR(cost, optimal, 0.02 * optimal);
  EXPECT_LT(cost, 0.75 * uniform);
}

TEST(AdaptiveSampleLimits, NoiselessPixelsStopAtTheMinimumAndNoisyOnesAtTheCap) {
  const auto zero = adaptive_sample_limits(std::vector<double>(size_t(kW) * kH, 0.0), kW, kH,
                                           {0.01f, 16, 1024});
  for (uint32_t v : zero) ASSERT_EQ(v, 16u);
  const auto huge = adaptive_sample_limits(std::vector<double>(size_t(kW) * kH, 1e6), kW, kH,
                                           {0.01f, 16, 1024});
  for (uint32_t v : huge) ASSERT_EQ(v, 1024u);
  std::vector<double> s(size_t(kW) * kH, 1.0);
  s[100] = INFINITY;  // not estimable yet: its neighbours cannot be judged and take the cap
  const auto n = adaptive_sample_limits(s, kW, kH, {0.1f, 16, 1024});
  for (size_t i : {99u, 101u, 100u - kW, 100u + kW + 1}) EXPECT_EQ(n[i], 1024u) << i;
  EXPECT_EQ(n[100], 100u);   // judged by its finite neighbours
  EXPECT_EQ(n[3000], 100u);  // the infinite pixel does not poison the others' mean
}

// A pixel's own samples never decide how many samples it gets: a count that depends on the
// values it averages biases the mean (a pixel stopping early because it has not met a rare bright
// path yet is dark on average). Its own deviation, from zero to huge, leaves its count alone.
TEST(AdaptiveSampleLimits, APixelsOwnDeviationNeverDecidesItsCount) {
  std::vector<double> s = two_regions(4.0, 1.0);
  for (size_t i = 0; i < s.size(); ++i) s[i] *= 1.0 + 0.3 * std::sin(double(i));  // uneven
  const size_t pixels[] = {size_t(10) * kW + 5, size_t(20) * kW + kW / 2, size_t(kH - 1) * kW};
  const auto base = adaptive_sample_limits(s, kW, kH, {0.05f, 16, 1000000});
  for (size_t p : pixels)
    for (double own : {0.0, 0.01, 3.0, 50.0}) {
      std::vector<double> t = s;
      t[p] = own;
      // Only through the image's mean deviation (the allocation's scale, 4096 pixels): by 1.2%
      // at most. The old rule, max(own, mean of the 3x3 window), moved it 11% at own = 0.
      const auto n = adaptive_sample_limits(t, kW, kH, {0.05f, 16, 1000000});
      EXPECT_NEAR(double(n[p]) / double(base[p]), 1.0, 0.015)
          << "pixel " << p << ", own deviation " << own;
    }
}

// A pixel that has not met a rare bright path yet reports a deviation near zero; its
// neighbourhood keeps it sampling.
TEST(AdaptiveSampleLimits, AnIsolatedQuietPixelIsJudgedByItsNeighbourhood) {
  std::vector<double> s(size_t(kW) * kH, 1.0);
  const size_t lone = size_t(20) * kW + 20;
  s[lone] = 0.0;
  const auto n = adaptive_sample_limits(s, kW, kH, {0.1f, 16, 100000});
  EXPECT_GE(n[lone], 0.85 * n[0]);
}

}  // namespace
}  // namespace penumbra::test
