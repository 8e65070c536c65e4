// Piecewise-constant distributions: sample() follows pdf() (chi-square), pdf() integrates to 1,
// sample() reports the density pdf() gives at the point, and degenerate weights (all zero,
// negative, NaN, one hot cell) produce no NaN, no Inf and no division by zero.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "renderer/sampling/distribution_2d.h"
#include "tests/renderer/sampling/chi2_util.h"

namespace penumbra::test {
namespace {

constexpr int kSamples = 200000;

TEST(Distribution1D, SamplesFollowTheWeights) {
  const std::vector<float> w = {1.f, 0.f, 3.f, 0.5f, 2.f, 0.f, 0.f, 7.f};
  const Distribution1D d(w);
  EXPECT_NEAR(d.integral(), 13.5 / 8.0, 1e-6);
  // Four bins per cell: the density must also be flat inside each cell.
  constexpr int kSub = 4;
  const int bins = int(w.size()) * kSub;
  std::vector<double> observed(size_t(bins), 0.0), expected(size_t(bins), 0.0);
  for (int b = 0; b < bins; ++b) expected[size_t(b)] = kSamples * w[size_t(b / kSub)] / 13.5 / kSub;
  Rng rng(7);
  for (int i = 0; i < kSamples; ++i) {
    float pdf = -1.f;
    int cell = -1;
    const float x = d.sample(rng.next(), &pdf, &cell);
    ASSERT_GE(x, 0.f);
    ASSERT_LT(x, 1.f);
    ASSERT_EQ(pdf, d.pdf(x));
    ASSERT_EQ(cell, std::min(int(x * w.size()), int(w.size()) - 1));
    observed[size_t(std::min(int(x * bins), bins - 1))] += 1.0;
  }
  const auto fit = chi2_goodness_of_fit(observed, expected);
  EXPECT_TRUE(fit.pass) << fit.message;
}

TEST(Distribution1D, PdfIntegratesToOne) {
  const std::vector<float> w = {0.2f, 5.f, 0.f, 1e-6f, 3.f};
  const Distribution1D d(w);
  double integral = 0.0;
  for (size_t i = 0; i < w.size(); ++i) integral += d.pdf((i + 0.5f) / w.size()) / double(w.size());
  EXPECT_NEAR(integral, 1.0, 1e-6);
  EXPECT_EQ(d.pdf(1.f), d.pdf(0.99f));  // x == 1 belongs to the last cell
}

TEST(Distribution1D, ExtremeRandomNumbersStayInTheSampledCell) {
  const std::vector<float> w = {1.f, 0.f, 0.f, 1.f, 1e-30f, 4.f};
  const Distribution1D d(w);
  for (float u : {0.f, 1e-9f, 0.2f, 0.25f, 0.5f, 0.75f, 0.9999f, kOneMinusEpsilon}) {
    float pdf = 0.f;
    int cell = -1;
    const float x = d.sample(u, &pdf, &cell);
    EXPECT_GE(x, 0.f);
    EXPECT_LT(x, 1.f);
    EXPECT_GT(pdf, 0.f) << "u = " << u;  // zero-weight cells are never chosen
    EXPECT_EQ(pdf, d.pdf(x));
    EXPECT_NE(cell, 1);
    EXPECT_NE(cell, 2);
  }
}

// Weights of four kinds (uniform-ish, one sun, mostly zero, twelve decades) and, for them, u on
// every CDF value and bucket edge and their float neighbours, random u, and u outside [0, 1):
// what the guided search and the SIMD lanes of sample_many / sample_rows / sample_columns must
// take exactly.
std::vector<float> shaped_weights(int n, int shape, uint32_t* state) {
  const auto next = [state] {
    *state = *state * 1664525u + 1013904223u;
    return float(*state >> 8) * 0x1p-24f;
  };
  std::vector<float> w(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const float r = next();
    w[size_t(i)] = shape == 0 ? r : shape == 1 ? (i == n / 3 ? 1e6f : r * 1e-3f)
                 : shape == 2 ? (r < 0.8f ? 0.f : r) : std::exp2(40.f * r - 20.f);
  }
  return w;
}

std::vector<float> probing_us(std::span<const float> cdf, int n, uint32_t* state) {
  std::vector<float> us;
  for (const float c : cdf) {
    us.push_back(c);
    us.push_back(std::nextafter(c, 0.f));
    us.push_back(std::nextafter(c, 1.f));
  }
  for (int k = 0; k <= 4 * n; ++k) {
    const float t = float(k) / float(4 * n);
    us.push_back(t);
    us.push_back(std::nextafter(t, 0.f));
  }
  for (int j = 0; j < 500; ++j) {
    *state = *state * 1664525u + 1013904223u;
    us.push_back(float(*state >> 8) * 0x1p-24f);
  }
  for (const float u : {-0.f, -1e-30f, -0.5f, 1.f, 1.5f, kOneMinusEpsilon, INFINITY, NAN}) us.push_back(u);
  return us;
}

// The guide table narrows the search; the cell must be the one a binary search over the whole CDF
// finds (the last cell whose CDF is <= u), so images do not change with it. Peaked weights (an
// environment map's sun), long runs of zeros, every size around the powers of two that set the
// table's length, and u on every CDF value, bucket edge and their float neighbours.
TEST(Distribution1D, GuidedSearchFindsTheCellOfTheFullSearch) {
  uint32_t state = 12345u;
  for (const int n : {1, 2, 3, 4, 5, 7, 8, 9, 31, 33, 64, 100, 255, 257, 512, 1000}) {
    for (int shape = 0; shape < 4; ++shape) {
      const Distribution1D d(shaped_weights(n, shape, &state));
      const std::span<const float> cdf = d.cdf();
      for (const float u : probing_us(cdf, n, &state)) {
        if (!(u >= 0.f && u < 1.f)) continue;
        const int expected = int(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()) - 1;
        int cell = -1;
        d.sample(u, nullptr, &cell);
        ASSERT_EQ(cell, std::clamp(expected, 0, n - 1)) << "n " << n << " shape " << shape << " u " << u;
      }
    }
  }
}

TEST(Distribution1D, SampleManyIsSampleToTheBit) {
  uint32_t state = 99u;
  for (const int n : {1, 2, 3, 5, 8, 9, 33, 100, 255, 512, 1000}) {
    for (int shape = 0; shape < 4; ++shape) {
      const Distribution1D d(shaped_weights(n, shape, &state));
      const std::vector<float> us = probing_us(d.cdf(), n, &state);
      std::vector<int> cells(us.size(), -1);
      std::vector<float> xs(us.size(), -1.f);
      d.sample_many(us.size(), us.data(), cells.data(), xs.data());
      for (size_t k = 0; k < us.size(); ++k) {
        int cell = -1;
        const float x = d.sample(us[k], nullptr, &cell);
        ASSERT_EQ(cells[k], cell) << "n " << n << " shape " << shape << " u " << us[k];
        ASSERT_EQ(std::bit_cast<uint32_t>(xs[k]), std::bit_cast<uint32_t>(x))
            << "n " << n << " shape " << shape << " u " << us[k];
      }
    }
  }
}

TEST(Distribution2D, SampleRowsAndColumnsAreSampleToTheBit) {
  uint32_t state = 7u;
  for (const int nu : {1, 3, 64, 257, 512}) {
    const int nv = 8;
    std::vector<float> w;
    for (int j = 0; j < nv; ++j) {
      const std::vector<float> row = shaped_weights(nu, j % 4, &state);
      w.insert(w.end(), row.begin(), row.end());
    }
    const Distribution2D d(w, nu, nv);
    std::vector<float> cdf_probe(size_t(nu) + 1);
    for (int i = 0; i <= nu; ++i) cdf_probe[size_t(i)] = float(i) / float(nu);
    const std::vector<float> us = probing_us(cdf_probe, nu, &state);
    std::vector<int> rows(us.size(), -1);
    std::vector<float> vs(us.size(), -1.f);
    d.sample_rows(us.size(), us.data(), rows.data(), vs.data());
    for (size_t k = 0; k < us.size(); ++k) {
      int row = -1;
      const float v = d.sample_row(us[k], &row);
      ASSERT_EQ(rows[k], row) << "u " << us[k];
      ASSERT_EQ(std::bit_cast<uint32_t>(vs[k]), std::bit_cast<uint32_t>(v)) << "u " << us[k];
    }
    for (int j = 0; j < nv; ++j) {
      const std::vector<int> row(us.size(), j);
      std::vector<int> columns(us.size(), -1);
      std::vector<float> xs(us.size(), -1.f);
      d.sample_columns(us.size(), row.data(), us.data(), columns.data(), xs.data());
      for (size_t k = 0; k < us.size(); ++k) {
        int column = -1;
        const float x = d.sample_column(j, us[k], &column);
        ASSERT_EQ(columns[k], column) << "nu " << nu << " row " << j << " u " << us[k];
        ASSERT_EQ(std::bit_cast<uint32_t>(xs[k]), std::bit_cast<uint32_t>(x))
            << "nu " << nu << " row " << j << " u " << us[k];
      }
    }
  }
}

TEST(Distribution1D, ZeroNegativeAndNonFiniteWeightsAreHarmless) {
  const std::vector<float> zeros(5, 0.f);
  const Distribution1D z(zeros);
  EXPECT_EQ(z.integral(), 0.0);
  float pdf = -1.f;
  const float x = z.sample(0.3f, &pdf);
  EXPECT_TRUE(x >= 0.f && x < 1.f);
  EXPECT_EQ(pdf, 0.f);  // callers reject pdf 0; nothing divided by zero
  EXPECT_EQ(z.pdf(0.5f), 0.f);

  const std::vector<float> bad = {-1.f, NAN, INFINITY, 2.f};
  const Distribution1D b(bad);
  EXPECT_EQ(b.integral(), 0.5);
  EXPECT_EQ(b.pdf(0.1f), 0.f);
  EXPECT_EQ(b.pdf(0.9f), 4.f);
  EXPECT_EQ(b.pdf(NAN), 0.f);  // a NaN coordinate reads cell 0, not out of bounds

  const Distribution1D empty(std::span<const float>{});
  EXPECT_EQ(empty.size(), 1u);
  EXPECT_EQ(empty.pdf(0.5f), 0.f);
}

TEST(Distribution2D, SamplesFollowTheWeights) {
  // 7 x 5 cells with a zero row, zero cells and a hot cell.
  constexpr int nu = 7, nv = 5;
  std::vector<float> w(nu * nv);
  Rng weights_rng(3);
  for (float& x : w) x = weights_rng.next();
  for (int i = 0; i < nu; ++i) w[2 * nu + i] = 0.f;
  w[4] = w[3 * nu + 6] = 0.f;
  w[1 * nu + 5] = 40.f;
  const Distribution2D d(w, nu, nv);
  double total = 0.0;
  for (float x : w) total += x;
  EXPECT_NEAR(d.integral(), total / (nu * nv), 1e-6);

  constexpr int kSub = 2;  // bins per cell and axis
  const int bu = nu * kSub, bv = nv * kSub;
  std::vector<double> observed(size_t(bu * bv), 0.0), expected(size_t(bu * bv), 0.0);
  for (int j = 0; j < bv; ++j)
    for (int i = 0; i < bu; ++i)
      expected[size_t(j * bu + i)] = kSamples * w[size_t((j / kSub) * nu + i / kSub)] / total / (kSub * kSub);
  Rng rng(11);
  for (int s = 0; s < kSamples; ++s) {
    float pdf = -1.f;
    glm::ivec2 cell(-1);
    const vec2 p = d.sample(rng.next2(), &pdf, &cell);
    ASSERT_TRUE(p.x >= 0.f && p.x < 1.f && p.y >= 0.f && p.y < 1.f);
    ASSERT_EQ(pdf, d.pdf(p));
    ASSERT_GT(pdf, 0.f);
    // The cell reported is the point's, and its density the point's.
    ASSERT_EQ(cell.x, int(p.x * nu));
    ASSERT_EQ(cell.y, int(p.y * nv));
    ASSERT_EQ(d.cell_pdf(cell.x, cell.y), pdf);
    observed[size_t(std::min(int(p.y * bv), bv - 1) * bu + std::min(int(p.x * bu), bu - 1))] += 1.0;
  }
  const auto fit = chi2_goodness_of_fit(observed, expected);
  EXPECT_TRUE(fit.pass) << fit.message;
}

TEST(Distribution2D, PdfIntegratesToOne) {
  constexpr int nu = 9, nv = 4;
  std::vector<float> w(nu * nv);
  for (int k = 0; k < nu * nv; ++k) w[size_t(k)] = float((k * 37) % 11);
  const Distribution2D d(w, nu, nv);
  double integral = 0.0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) integral += d.pdf(vec2((i + 0.5f) / nu, (j + 0.5f) / nv)) / (nu * nv);
  EXPECT_NEAR(integral, 1.0, 1e-5);
}

TEST(Distribution2D, OneHotCellAndAllZeroAreHarmless) {
  constexpr int nu = 64, nv = 32;
  std::vector<float> w(nu * nv, 0.f);
  w[size_t(17 * nu + 40)] = 1e30f;
  const Distribution2D hot(w, nu, nv);
  Rng rng(5);
  for (int s = 0; s < 1000; ++s) {
    float pdf = 0.f;
    const vec2 p = hot.sample(rng.next2(), &pdf);
    ASSERT_EQ(int(p.x * nu), 40);
    ASSERT_EQ(int(p.y * nv), 17);
    ASSERT_NEAR(pdf, float(nu * nv), 1e-3f * nu * nv);
  }
  const Distribution2D zero(std::vector<float>(nu * nv, 0.f), nu, nv);
  float pdf = -1.f;
  const vec2 p = zero.sample(vec2(0.5f, 0.5f), &pdf);
  EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
  EXPECT_EQ(pdf, 0.f);
  EXPECT_EQ(zero.pdf(vec2(0.3f, 0.7f)), 0.f);
  // Rows the weights do not reach weigh nothing: the two given rows share all the density.
  const Distribution2D short_rows(std::vector<float>(size_t(2 * nu), 1.f), nu, nv);
  EXPECT_FLOAT_EQ(short_rows.pdf(vec2(0.5f, 0.5f / nv)), float(nv) / 2.f);
  EXPECT_EQ(short_rows.pdf(vec2(0.5f, 0.5f)), 0.f);
  for (int s = 0; s < 100; ++s) EXPECT_LT(short_rows.sample(rng.next2(), &pdf).y, 2.f / nv);
  // A single cell is the uniform distribution.
  const Distribution2D one(std::vector<float>{2.f}, 1, 1);
  EXPECT_EQ(one.pdf(vec2(0.1f, 0.9f)), 1.f);
}

// The table built from blocks of rows on all cores (the form an environment map uses) is the
// one-row-at-a-time table to the bit, whatever the blocks: a reference built here row by row
// (each row a Distribution1D, the marginal over their integrals in row order, the joint density
// their product), against blocks of 1, 2, 3 and 7 rows (the last one shorter where nv is no
// multiple), one block of all rows, more rows per block than there are, and the automatic
// choice; one-row and one-column tables, and sizes around the guide's powers of two. Every row
// must be put exactly once, by the block that holds it.
TEST(Distribution2D, BlocksOfRowsGiveTheOneRowAtATimeTableToTheBit) {
  uint32_t state = 11u;
  const auto bits = [](float v) { return std::bit_cast<uint32_t>(v); };
  for (const auto& [nu, nv] : std::vector<std::pair<int, int>>{
           {1, 1}, {1, 23}, {7, 1}, {64, 1}, {5, 23}, {64, 37}, {257, 9}, {3, 100}, {1000, 70}}) {
    std::vector<std::vector<float>> rows;
    for (int j = 0; j < nv; ++j) rows.push_back(shaped_weights(nu, (j * 7 + nu) % 4, &state));
    if (nv > 2) rows[size_t(nv / 2)].assign(size_t(nu), 0.f);  // a row that weighs nothing
    // The reference, one row at a time.
    std::vector<Distribution1D> conditional;
    std::vector<float> integrals;
    for (const auto& w : rows) {
      conditional.emplace_back(w);
      integrals.push_back(float(conditional.back().integral()));
    }
    const Distribution1D marginal(integrals);
    for (const int per_block : {1, 2, 3, 7, nv, nv + 5, 0}) {
      std::mutex mutex;
      std::vector<int> put_count(size_t(nv), 0);
      std::vector<std::pair<int, int>> blocks;
      const Distribution2D d(nu, nv, [&](int begin, int end, const Distribution2D::RowPut& put) {
        {
          std::lock_guard<std::mutex> lock(mutex);
          blocks.emplace_back(begin, end);
        }
        for (int j = begin; j < end; ++j) {
          put(j, rows[size_t(j)]);
          std::lock_guard<std::mutex> lock(mutex);
          ++put_count[size_t(j)];
        }
      }, per_block);
      const std::string where = "nu " + std::to_string(nu) + " nv " + std::to_string(nv) +
                                " rows per block " + std::to_string(per_block);
      // The blocks tile [0, nv) in order of their starts, each of per_block rows but the last.
      std::sort(blocks.begin(), blocks.end());
      ASSERT_FALSE(blocks.empty()) << where;
      EXPECT_EQ(blocks.front().first, 0) << where;
      EXPECT_EQ(blocks.back().second, nv) << where;
      for (size_t b = 0; b + 1 < blocks.size(); ++b) {
        EXPECT_EQ(blocks[b].second, blocks[b + 1].first) << where;
        if (per_block > 0) EXPECT_EQ(blocks[b].second - blocks[b].first, per_block) << where;
      }
      for (int j = 0; j < nv; ++j) ASSERT_EQ(put_count[size_t(j)], 1) << where << " row " << j;
      // Every number of the table.
      ASSERT_EQ(d.nu(), nu);
      ASSERT_EQ(d.nv(), nv);
      EXPECT_EQ(d.integral(), marginal.integral()) << where;
      for (int j = 0; j <= nv; ++j) ASSERT_EQ(bits(d.marginal().cdf()[size_t(j)]), bits(marginal.cdf()[size_t(j)])) << where;
      int steps = 0;
      for (int j = 0; j < nv; ++j) {
        const Distribution1D& c = conditional[size_t(j)];
        steps = std::max(steps, c.search_steps());
        ASSERT_EQ(d.row_cdf(j).size(), c.cdf().size()) << where;
        for (size_t i = 0; i < c.cdf().size(); ++i)
          ASSERT_EQ(bits(d.row_cdf(j)[i]), bits(c.cdf()[i])) << where << " row " << j << " edge " << i;
        ASSERT_TRUE(std::equal(c.guide().begin(), c.guide().end(), d.row_guide(j).begin(), d.row_guide(j).end()))
            << where << " row " << j;
        for (int i = 0; i < nu; ++i)
          ASSERT_EQ(bits(d.cell_pdf(i, j)), bits(marginal.cell_pdf(j) * c.cell_pdf(i)))
              << where << " cell " << i << ", " << j;
      }
      EXPECT_EQ(d.search_steps(), steps) << where;
    }
  }
}

}  // namespace
}  // namespace penumbra::test
