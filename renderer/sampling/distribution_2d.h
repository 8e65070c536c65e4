#pragma once
// Piecewise-constant distributions on [0, 1) and [0, 1)^2, sampled by inverting their CDFs
// (pbrt-v4 §A.4-A.5, PiecewiseConstant1D / PiecewiseConstant2D). Used to sample an environment map
// in proportion to its luminance; reusable for anything tabulated on a grid.
//
// The inversion starts from a guide table (the cutpoint method of Chen & Asau 1974; Devroye 1986
// §III.2.4): for each of K equal intervals of u, the cell its lower end falls in. A search then
// only spans the cells between two neighbouring entries -- on average n / K of them, however
// peaked the weights -- instead of a binary search over all n cells, whose data-dependent
// branches and scattered loads made it the environment map's largest cost. The cell found is the
// same as the full search's (the last cell whose CDF is <= u), so images do not change.
//
// Robustness: negative or non-finite weights count as 0. A distribution whose weights are all
// zero still samples (uniformly) but reports pdf 0 for every point, so a caller that divides by
// the pdf must reject pdf == 0; nothing here divides by zero.
#include <algorithm>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "renderer/core/default_init_allocator.h"
#include "renderer/core/math.h"

namespace penumbra {

// The inversion of a piecewise-constant CDF through its guide table, wherever the table is kept:
// Distribution1D's own arrays, or one row of Distribution2D's flat ones.
struct CdfSearch {
  const float* cdf = nullptr;  // n + 1 values from 0 to 1
  const int* guide = nullptr;  // buckets + 1 entries (see Distribution1D::guide_)
  size_t n = 0, buckets = 0;

  // The last cell i with cdf[i] <= u (0 for u < 0, n - 1 for u >= 1 or NaN).
  int find_cell(float u) const;
  // x in [0, 1) in the cell find_cell(u) picks, placed linearly by u within it; *cell gets it.
  float sample(float u, int* cell) const;
};

class Distribution1D {
 public:
  Distribution1D() = default;
  // n = weights.size() >= 1 equal cells over [0, 1); cell i has density proportional to weights[i].
  explicit Distribution1D(std::span<const float> weights);

  size_t size() const { return pdf_.size(); }
  // Integral of the (cleaned) weights over [0, 1): their mean. 0 = nothing to sample.
  double integral() const { return integral_; }
  // x in [0, 1) with density pdf(x); *cell (if given) receives the cell x lies in.
  float sample(float u, float* pdf, int* cell = nullptr) const;
  // sample() for m values of u at once in SIMD lanes, to the bit (no densities: cell_pdf).
  void sample_many(size_t m, const float* u, int* cell, float* x) const;
  // Density at x in [0, 1] (x == 1 counts as the last cell).
  float pdf(float x) const;
  // The CDF at the cells' edges: n + 1 values from 0 to 1.
  std::span<const float> cdf() const { return cdf_; }
  // Density of cell i (constant over it).
  float cell_pdf(int i) const { return pdf_[size_t(i)]; }
  // The guide table, one entry per bucket plus the end (see guide_).
  std::span<const int> guide() const { return guide_; }
  // The halvings sample_many's search takes (the widest range of the guide).
  int search_steps() const { return search_steps_; }

 private:
  CdfSearch search() const {
    return {cdf_.data(), guide_.data(), pdf_.size(), guide_.empty() ? 0 : guide_.size() - 1};
  }

  // Each cell's density, weight / integral (0 for all cells when the integral is 0): divided
  // once here, not per lookup (a double division was half of a map's pdf() time).
  std::vector<float> pdf_;
  std::vector<float> cdf_;  // size n + 1, cdf_[0] = 0, cdf_[n] = 1
  // guide_[k] = find_cell(k / K) for k = 0..K, K = guide_.size() - 1 a power of two, so that
  // k / K and u * K are exact in float and u in [k / K, (k + 1) / K) lies in cells
  // guide_[k]..guide_[k + 1].
  std::vector<int> guide_;
  int search_steps_ = 0;  // halvings that bring the guide's widest range to one cell
  double integral_ = 0.0;
};

class Distribution2D {
 public:
  Distribution2D() = default;
  // `weights` is row-major with `nu` cells per row and `nv` rows: the cell (i, j) covers
  // [i/nu, (i+1)/nu) x [j/nv, (j+1)/nv). A marginal distribution picks the row (v), then that
  // row's conditional distribution picks u.
  Distribution2D(std::span<const float> weights, int nu, int nv);
  // The same from the rows' weights as a caller computes them, block by block: rows(begin, end,
  // put) computes rows begin..end - 1 in order and hands each to put(j, weights) (nu cells), so a
  // caller needs no nu x nv array (an 8192 x 4096 environment map's would be 134 MB). The blocks
  // (of rows_per_block rows; 0: renderer/core/row_blocks.h's choice) run concurrently on all
  // cores, each row's conditional distribution built as its block puts it; the marginal over the
  // rows is built after them all, in row order. A caller keeps whatever it carries from row to
  // row local to its block. Every number is the same to the bit however the rows are split.
  using RowPut = std::function<void(int, std::span<const float>)>;
  using RowBlock = std::function<void(int, int, const RowPut&)>;
  Distribution2D(int nu, int nv, const RowBlock& rows, int rows_per_block = 0);

  int nu() const { return nu_; }
  int nv() const { return nv_; }
  // Integral of the weights over [0, 1)^2: their mean.
  double integral() const { return marginal_.integral(); }
  // A point of [0, 1)^2 with density *pdf (0 when the distribution is all zero); *cell (if
  // given) receives the cell it lies in, as (column, row).
  vec2 sample(const vec2& u, float* pdf, glm::ivec2* cell = nullptr) const;
  // sample() in its two steps: v (with its row) from u.y, then x (with its column) within that
  // row from u.x; the point (x, v) lies in cell (column, row).
  float sample_row(float u, int* row) const { return marginal_.sample(u, nullptr, row); }
  float sample_column(int row, float u, int* column) const;
  // The same for m samples at once in SIMD lanes, to the bit: every v and row from u[k], then
  // every x and column within row[k].
  void sample_rows(size_t m, const float* u, int* row, float* v) const { marginal_.sample_many(m, u, row, v); }
  void sample_columns(size_t m, const int* row, const float* u, int* column, float* x) const;
  // Density at p in [0, 1]^2.
  float pdf(const vec2& p) const;
  // Density of cell (i, j), constant over it.
  float cell_pdf(int i, int j) const { return pdf_[size_t(j) * size_t(nu_) + size_t(i)]; }
  // Row j's conditional CDF (nu + 1 values) and guide table: for tests.
  std::span<const float> row_cdf(int j) const { return {cdf_.data() + size_t(j) * size_t(nu_ + 1), size_t(nu_ + 1)}; }
  std::span<const int> row_guide(int j) const { return {guide_.data() + size_t(j) * (buckets_ + 1), buckets_ + 1}; }
  const Distribution1D& marginal() const { return marginal_; }
  // The halvings sample_columns' search takes (the widest range of any row's guide).
  int search_steps() const { return search_steps_; }
  // Hints that cell_pdf(i, j), or sample_column(row, u)'s first load, will be read soon: a caller
  // with many samples issues them for all before it reads any, so their cache misses overlap.
  void prefetch_cell(int i, int j) const { __builtin_prefetch(&pdf_[size_t(j) * size_t(nu_) + size_t(i)]); }
  // (sample_column's search reads the row's guide entry for u first. A second hint for the CDF
  // from there, once the entry is in cache, was measured and gains nothing more.)
  void prefetch_column(int row, float u) const {
    if (buckets_ > 0) __builtin_prefetch(&guide_[guide_index(row, u)]);
  }

 private:
  // The guide entry of u in [0, 1) in row `row` (the one CdfSearch::find_cell reads first;
  // anything else is clamped into the row).
  size_t guide_index(int row, float u) const {
    const size_t k = u > 0.f ? std::min(size_t(std::min(u, 1.f) * float(buckets_)), buckets_ - 1) : 0;
    return size_t(row) * (buckets_ + 1) + k;
  }

  int nu_ = 0, nv_ = 0;
  // The rows' conditional distributions, flat: row j's CDF is cdf_[j * (nu + 1) ...], its guide
  // guide_[j * (buckets + 1) ...]. One array per kind instead of a Distribution1D per row
  // saves a sample the load of the row's own pointers before the search can start (the map's
  // sampling is a chain of dependent loads).
  // (Uninitialised when sized: every value is written once, by its row's block.)
  std::vector<float, DefaultInitAllocator<float>> cdf_;
  std::vector<int, DefaultInitAllocator<int>> guide_;
  size_t buckets_ = 0;
  int search_steps_ = 0;  // halvings that bring the widest range of any row's guide to one cell
  // The joint density of every cell, marginal x conditional (the product sample and pdf return),
  // so a pdf is one load.
  std::vector<float, DefaultInitAllocator<float>> pdf_;
  Distribution1D marginal_;  // over rows, weighted by each row's integral
};

}  // namespace penumbra
