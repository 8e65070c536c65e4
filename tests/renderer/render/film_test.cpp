// The film's accumulation: a run of one pixel's samples added at once (add_samples, the wavefront
// driver's way) must leave exactly the sums, counts and variances that adding them one by one
// (add_sample, the scalar driver's way) leaves, non-finite samples dropped by both.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "renderer/render/film.h"
#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

TEST(Film, RunOfSamplesIsSamplesOneByOneToTheBit) {
  Rng rng(23);
  std::vector<Spectrum> values(200);
  // Values over many magnitudes, so that the order of the additions shows in the rounding.
  for (Spectrum& v : values)
    v = Spectrum(rng.next() * 1e3f, rng.next() * 1e-3f, std::ldexp(rng.next(), int(rng.next() * 40) - 20));
  values[7] = Spectrum(std::numeric_limits<float>::quiet_NaN(), 1.f, 1.f);
  values[150] = Spectrum(1.f, std::numeric_limits<float>::infinity(), 1.f);
  Film one(3, 2), runs(3, 2);
  uint32_t dropped_one = 0, dropped_runs = 0;
  // Pixel (2, 1) takes runs of 1, 13 and the rest; pixel (0, 0) one sample before them.
  one.add_sample(0, 0, Spectrum(0.5f));
  runs.add_samples(0, 0, 1, [](size_t) { return Spectrum(0.5f); });
  for (const Spectrum& v : values) dropped_one += one.add_sample(2, 1, v) ? 0 : 1;
  size_t start = 0;
  for (const size_t length : {size_t(1), size_t(13), values.size() - 14}) {
    dropped_runs += runs.add_samples(2, 1, length, [&](size_t k) -> const Spectrum& { return values[start + k]; });
    start += length;
  }
  EXPECT_EQ(dropped_one, 2u);
  EXPECT_EQ(dropped_runs, 2u);
  EXPECT_EQ(one.samples(2, 1), runs.samples(2, 1));
  EXPECT_EQ(runs.samples(2, 1), 198u);
  EXPECT_EQ(runs.samples(0, 0), 1u);
  EXPECT_EQ(runs.samples(1, 1), 0u);
  const Image a = one.resolve(), b = runs.resolve();
  const Image va = one.resolve_variance(), vb = runs.resolve_variance();
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    EXPECT_EQ(a.rgb[i], b.rgb[i]) << i;
    EXPECT_EQ(va.rgb[i], vb.rgb[i]) << i;
  }
  EXPECT_EQ(one.relative_deviation(2, 1), runs.relative_deviation(2, 1));
}

}  // namespace
}  // namespace penumbra::test
