// The warps' own arithmetic: the polynomial sines and cosines (of the concentric map's angles and
// of 2 pi u) against libm in double, and the concentric map against its polar definition.
#include "renderer/sampling/sampling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace penumbra::test {
namespace {

// Distance in float ulps between a float and the exact (double) value.
double ulps(float got, double exact) {
  const double ulp = std::nextafter(float(std::abs(exact)), INFINITY) - float(std::abs(exact));
  return std::abs(double(got) - exact) / ulp;
}

TEST(SamplingWarps, SinCosQuarterPi) {
  double worst_s = 0.0, worst_c = 0.0;
  const int n = 1 << 20;
  for (int i = -n; i <= n; ++i) {
    const float x = float(double(kPi) / 4.0 * i / n);
    float s, c;
    sincos_quarter_pi(x, &s, &c);
    if (x != 0.f) worst_s = std::max(worst_s, ulps(s, std::sin(double(x))));
    worst_c = std::max(worst_c, ulps(c, std::cos(double(x))));
    ASSERT_LE(std::abs(s), 1.f);
    ASSERT_LE(c, 1.f);
  }
  // The rounding of the Horner steps costs about one ulp (libm: half); dropping the last term of
  // the sine already costs six, any earlier term far more.
  EXPECT_LE(worst_s, 1.5);
  EXPECT_LE(worst_c, 1.5);
  float s, c;
  sincos_quarter_pi(0.f, &s, &c);
  EXPECT_EQ(s, 0.f);
  EXPECT_EQ(c, 1.f);
}

TEST(SamplingWarps, SinCosTwoPi) {
  // Against sin and cos of 2 pi u in double: the reduction is exact, so the error is the
  // polynomial's plus one rounding of the reduced angle, in absolute terms (the result's ulp near
  // a zero crossing is far below the input's resolution, which no float method has either).
  double worst = 0.0;
  const int n = 1 << 20;
  for (int i = -n; i <= 2 * n; ++i) {
    const float u = float(i) / n + 0.3f / n;
    float s, c;
    sincos_two_pi(u, &s, &c);
    const double a = 2.0 * M_PI * double(u);
    worst = std::max({worst, std::abs(s - std::sin(a)), std::abs(c - std::cos(a))});
  }
  EXPECT_LT(worst, 1.3e-7);
  // Quarter turns exactly, the quadrant order included (a swapped case fails these).
  const float quarter[][3] = {{0.f, 0.f, 1.f}, {0.25f, 1.f, 0.f}, {0.5f, 0.f, -1.f},
                              {0.75f, -1.f, 0.f}, {1.f, 0.f, 1.f}, {-0.25f, -1.f, 0.f}};
  for (const auto& q : quarter) {
    float s, c;
    sincos_two_pi(q[0], &s, &c);
    EXPECT_EQ(s, q[1]) << q[0];
    EXPECT_EQ(c, q[2]) << q[0];
  }
  float s, c;
  sincos_two_pi(0.125f, &s, &c);
  EXPECT_NEAR(s, std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(c, std::sqrt(0.5), 1e-7);
  sincos_two_pi(0.625f, &s, &c);
  EXPECT_NEAR(s, -std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(c, -std::sqrt(0.5), 1e-7);
}

TEST(SamplingWarps, ConcentricMapMatchesItsPolarForm) {
  // Shirley & Chiu: r = ox, phi = pi/4 oy/ox where |ox| > |oy|; else r = oy, phi = pi/2 - pi/4 ox/oy.
  double worst = 0.0;
  const int n = 512;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const vec2 u((i + 0.5f) / n, (j + 0.3f) / n);
      const vec2 d = square_to_disk_concentric(u);
      const double ox = 2.0 * u.x - 1.0, oy = 2.0 * u.y - 1.0;
      double r, phi;
      if (std::abs(ox) > std::abs(oy)) {
        r = ox;
        phi = M_PI / 4 * (oy / ox);
      } else {
        r = oy;
        phi = M_PI / 2 - M_PI / 4 * (ox / oy);
      }
      worst = std::max({worst, std::abs(d.x - r * std::cos(phi)), std::abs(d.y - r * std::sin(phi))});
      ASSERT_LE(d.x * d.x + d.y * d.y, 1.f + 1e-6f);
    }
  EXPECT_LT(worst, 4e-7);
  EXPECT_EQ(square_to_disk_concentric(vec2(0.5f)), vec2(0.f));
}

}  // namespace
}  // namespace penumbra::test
