#include "renderer/sampling/distribution_2d.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "renderer/core/row_blocks.h"
#include "renderer/core/simd_clones.h"

namespace penumbra {
namespace {

float clean(float w) { return std::isfinite(w) && w > 0.f ? w : 0.f; }

// The cell of x in [0, 1] among n equal cells (x == 1, and anything above, belongs to the last;
// NaN to the first). In int32 arithmetic with the float clamped first, so that the SIMD lanes
// below use it too (vector units have no float-to-unsigned conversion).
int32_t cell_of(float x, int32_t n) {
  const float scaled = x * float(n);
  return scaled > 0.f ? std::min(int32_t(std::min(scaled, float(n))), n - 1) : 0;
}

// CdfSearch::sample for many u at once, in SIMD lanes (target clones; the guide entries and CDF
// values are gathers): lane k searches the CDF at cdf + cdf_base[k] (n + 1 values) through the
// guide at guide + guide_base[k] (buckets + 1 entries); a null base array means 0 for all. The
// search halves the guide's range `steps` times by selects -- steps is enough for the widest
// range of the guide, and a lane whose range is already one cell wide keeps it -- then finishes
// as CdfSearch::sample does, one step of its rounding fix-up included. The answer is the same
// cell and x to the bit (the last cell whose CDF is <= u is unique, the arithmetic is
// sample()'s); a lane outside that (u outside [0, 1) or NaN, a fix-up of more than one step)
// is flagged in `redo` for the caller to take through CdfSearch::sample.
PENUMBRA_SIMD_CLONES
void cdf_sample_lanes(size_t m, const float* __restrict cdf, const int* __restrict guide,
                      const int32_t* __restrict cdf_base, const int32_t* __restrict guide_base,
                      int32_t n, int32_t buckets, int steps, const float* __restrict u,
                      int32_t* __restrict cell, float* __restrict x, int32_t* __restrict redo) {
  // (Loops over the lanes innermost, each its own pass: GCC vectorises only innermost loops.)
  constexpr size_t kLanes = 64;  // m <= kLanes
  int32_t cb[kLanes], first[kLanes], len[kLanes];
  float uc[kLanes];
  for (size_t k = 0; k < m; ++k) {
    cb[k] = cdf_base ? cdf_base[k] : 0;
    const int32_t gb = guide_base ? guide_base[k] : 0;
    const float uk = u[k];
    const bool in_range = uk >= 0.f && uk < 1.f;
    uc[k] = in_range ? uk : 0.f;
    redo[k] = in_range ? 0 : 1;
    const int32_t b = std::min(int32_t(uc[k] * float(buckets)), buckets - 1);
    const int32_t lo = guide[gb + b], hi = guide[gb + b + 1];
    // The first of cdf[lo + 1 .. hi] above u lies in [first, first + len].
    first[k] = lo + 1;
    len[k] = hi - lo;
  }
  for (int step = 0; step < steps; ++step)
    for (size_t k = 0; k < m; ++k) {
      const int32_t half = len[k] >> 1;
      // (half = 0 reads cdf[first - 1], a valid index, and moves nothing.)
      const bool up = cdf[cb[k] + first[k] + half - 1] <= uc[k];
      first[k] = up ? first[k] + half : first[k];
      len[k] = len[k] - half;
    }
  for (size_t k = 0; k < m; ++k) {
    // (len is 0 or 1 here; cdf[first] is at most cdf[n].)
    const float next = cdf[cb[k] + first[k]];  // read by every lane: a gather without a mask
    const int32_t i = first[k] - 1 + (len[k] == 1 && next <= uc[k] ? 1 : 0);
    const float c0 = cdf[cb[k] + i], c1 = cdf[cb[k] + i + 1];
    const float width = c1 - c0;
    float du = width > 0.f ? (uc[k] - c0) / width : 0.f;
    du = std::clamp(du, 0.f, kOneMinusEpsilon);
    float xi = std::min((float(i) + du) / float(n), kOneMinusEpsilon);
    // sample()'s fix-up: rounding may carry x onto the next cell's edge, where pdf(x) would find
    // the next cell; one step down (the next float towards 0) as a select.
    const bool fix = xi > 0.f && cell_of(xi, n) > i;
    xi = fix ? std::bit_cast<float>(std::bit_cast<int32_t>(xi) - 1) : xi;
    cell[k] = i;
    x[k] = xi;
    redo[k] = redo[k] || (xi > 0.f && cell_of(xi, n) > i) || len[k] > 1 ? 1 : 0;
  }
}

// The number of halvings that bring the widest of a guide's ranges to one cell.
int guide_search_steps(std::span<const int> guide, size_t buckets) {
  int widest = 1;
  for (size_t start = 0; start + buckets < guide.size(); start += buckets + 1)
    for (size_t k = 0; k < buckets; ++k) widest = std::max(widest, guide[start + k + 1] - guide[start + k]);
  int steps = 0;
  for (int len = widest; len > 1; len -= len >> 1) ++steps;
  return steps;
}

// The guide's number of buckets for n cells: about one entry per four cells, so a search spans
// ~4 cells on average (two comparisons), for a quarter more memory than the CDF alone; a power
// of two (see Distribution1D::guide_).
size_t guide_buckets(size_t n) { return std::max<size_t>(std::bit_ceil(n) / 4, 1); }

}  // namespace

Distribution1D::Distribution1D(std::span<const float> weights) {
  const size_t n = std::max<size_t>(weights.size(), 1);
  std::vector<float> func(n, 0.f);
  for (size_t i = 0; i < weights.size(); ++i) func[i] = clean(weights[i]);
  // Sums in double: a 16k-cell row of float sums would lose the small cells' share.
  std::vector<double> acc(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) acc[i + 1] = acc[i] + double(func[i]);
  const double total = acc[n];
  integral_ = total / double(n);
  cdf_.resize(n + 1);
  for (size_t i = 0; i <= n; ++i)
    cdf_[i] = total > 0.0 ? float(acc[i] / total) : float(double(i) / double(n));
  cdf_[n] = 1.f;
  pdf_.resize(n);
  for (size_t i = 0; i < n; ++i) pdf_[i] = integral_ > 0.0 ? float(double(func[i]) / integral_) : 0.f;
  const size_t buckets = guide_buckets(n);
  guide_.resize(buckets + 1);
  size_t i = 0;
  for (size_t k = 0; k <= buckets; ++k) {
    const float t = float(double(k) / double(buckets));  // exact: buckets is a power of two
    while (i + 1 < n && cdf_[i + 1] <= t) ++i;
    guide_[k] = int(i);
  }
  search_steps_ = guide_search_steps(guide_, buckets);
}

void Distribution1D::sample_many(size_t m, const float* u, int* cell, float* x) const {
  const CdfSearch search = this->search();
  if (search.buckets == 0) {  // default-constructed: no cells, CdfSearch's own answer
    for (size_t k = 0; k < m; ++k) x[k] = search.sample(u[k], &cell[k]);
    return;
  }
  constexpr size_t kChunk = 64;
  for (size_t k0 = 0; k0 < m; k0 += kChunk) {
    const size_t c = std::min(kChunk, m - k0);
    int32_t redo[kChunk];
    cdf_sample_lanes(c, cdf_.data(), guide_.data(), nullptr, nullptr, int32_t(pdf_.size()),
                     int32_t(search.buckets), search_steps_, u + k0, cell + k0, x + k0, redo);
    for (size_t k = 0; k < c; ++k)
      if (redo[k]) x[k0 + k] = search.sample(u[k0 + k], &cell[k0 + k]);
  }
}

int CdfSearch::find_cell(float u) const {
  if (buckets == 0) return 0;  // default-constructed: no cells
  if (!(u >= 0.f && u < 1.f)) {
    // Outside [0, 1) (and NaN): the binary search over all cells decides, clamped to a cell.
    const float* it = std::upper_bound(cdf, cdf + n + 1, u);
    return int(std::clamp<std::ptrdiff_t>(it - cdf - 1, 0, std::ptrdiff_t(n) - 1));
  }
  // u * buckets is exact (a power of two), so k / buckets <= u < (k + 1) / buckets.
  const size_t k = std::min(size_t(u * float(buckets)), buckets - 1);
  const size_t lo = size_t(guide[k]), hi = size_t(guide[k + 1]);
  // The last i in [lo, hi] with cdf[i] <= u: cdf[lo] <= k / buckets <= u, and no cell past hi
  // can qualify since cdf[hi + 1] > (k + 1) / buckets > u (or hi = n - 1).
  return int(std::upper_bound(cdf + lo + 1, cdf + hi + 1, u) - cdf) - 1;
}

float CdfSearch::sample(float u, int* cell) const {
  // The last cell i with cdf[i] <= u: cells of zero width (zero weight) are never chosen.
  const int i = find_cell(u);
  const float width = cdf[size_t(i) + 1] - cdf[size_t(i)];
  float du = width > 0.f ? (u - cdf[size_t(i)]) / width : 0.f;
  du = std::clamp(du, 0.f, kOneMinusEpsilon);
  float x = std::min((float(i) + du) / float(n), kOneMinusEpsilon);
  // Rounding may carry x onto the next cell's edge; pdf(x) must find the cell sampled here.
  while (x > 0.f && cell_of(x, int32_t(n)) > i) x = std::nextafter(x, 0.f);
  *cell = i;
  return x;
}

float Distribution1D::sample(float u, float* pdf, int* cell) const {
  int i = 0;
  const float x = search().sample(u, &i);
  if (pdf) *pdf = cell_pdf(i);
  if (cell) *cell = i;
  return x;
}

float Distribution1D::pdf(float x) const { return cell_pdf(cell_of(x, int32_t(pdf_.size()))); }

Distribution2D::Distribution2D(std::span<const float> weights, int nu, int nv)
    : Distribution2D(nu, nv, [&](int begin, int end, const RowPut& put) {
        std::vector<float> row(size_t(std::max(nu, 1)));
        for (int j = begin; j < end; ++j) {
          // A row past the end of `weights` weighs 0.
          const size_t first = size_t(j) * row.size();
          for (size_t i = 0; i < row.size(); ++i)
            row[i] = first + row.size() <= weights.size() ? weights[first + i] : 0.f;
          put(j, row);
        }
      }) {}

Distribution2D::Distribution2D(int nu, int nv, const RowBlock& rows, int rows_per_block)
    : nu_(std::max(nu, 1)), nv_(std::max(nv, 1)) {
  const size_t n = size_t(nu_);
  buckets_ = guide_buckets(n);  // the same for every row: it depends on nu alone
  // Sized whole, so that each row's block writes its own slices of them. pdf_ holds each cell's
  // density within its row at first; multiplied by its row's marginal density in place below,
  // it becomes the joint density (an 8192 x 4096 map's table is 134 MB: one array, not two).
  cdf_.resize(size_t(nv_) * (n + 1));
  guide_.resize(size_t(nv_) * (buckets_ + 1));
  pdf_.resize(size_t(nv_) * n);
  std::vector<float> row_integrals(static_cast<size_t>(nv_));
  std::vector<int> row_steps(static_cast<size_t>(nv_));
  const RowPut put = [&](int j, std::span<const float> weights) {
    // Each row built as a Distribution1D of its own, then copied into the flat arrays: the same
    // numbers, so the same samples, as one object per row.
    const Distribution1D d(weights);  // nu cells (the contract of RowBlock)
    std::copy(d.cdf().begin(), d.cdf().end(), cdf_.begin() + std::ptrdiff_t(size_t(j) * (n + 1)));
    std::copy(d.guide().begin(), d.guide().end(), guide_.begin() + std::ptrdiff_t(size_t(j) * (buckets_ + 1)));
    float* pdf = pdf_.data() + size_t(j) * n;
    for (size_t i = 0; i < n; ++i) pdf[i] = d.cell_pdf(int(i));
    row_integrals[size_t(j)] = float(d.integral());
    row_steps[size_t(j)] = d.search_steps();
  };
  for_row_blocks(size_t(nv_), rows_per_block > 0 ? size_t(rows_per_block) : penumbra::rows_per_block(n),
                 [&](size_t begin, size_t end) { rows(int(begin), int(end), put); });
  // The rows' integrals are all in: the marginal, then the joint densities (each cell's product
  // on its own, so again by blocks of rows).
  marginal_ = Distribution1D(row_integrals);
  // (The most halvings any row needs: the same as counting them for the widest range of all.)
  search_steps_ = *std::max_element(row_steps.begin(), row_steps.end());
  for_row_blocks(size_t(nv_), penumbra::rows_per_block(n), [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      float* pdf = pdf_.data() + j * n;
      const float row_pdf = marginal_.cell_pdf(int(j));
      for (size_t i = 0; i < n; ++i) pdf[i] = row_pdf * pdf[i];
    }
  });
}

float Distribution2D::sample_column(int row, float u, int* column) const {
  const CdfSearch conditional{cdf_.data() + size_t(row) * size_t(nu_ + 1),
                              guide_.data() + size_t(row) * (buckets_ + 1), size_t(nu_), buckets_};
  return conditional.sample(u, column);
}

void Distribution2D::sample_columns(size_t m, const int* row, const float* u, int* column, float* x) const {
  if (buckets_ == 0) {  // default-constructed: no rows
    for (size_t k = 0; k < m; ++k) x[k] = sample_column(row[k], u[k], &column[k]);
    return;
  }
  constexpr size_t kChunk = 64;
  for (size_t k0 = 0; k0 < m; k0 += kChunk) {
    const size_t c = std::min(kChunk, m - k0);
    int32_t cdf_base[kChunk], guide_base[kChunk], redo[kChunk];
    for (size_t k = 0; k < c; ++k) {
      cdf_base[k] = int32_t(size_t(row[k0 + k]) * size_t(nu_ + 1));
      guide_base[k] = int32_t(size_t(row[k0 + k]) * (buckets_ + 1));
    }
    cdf_sample_lanes(c, cdf_.data(), guide_.data(), cdf_base, guide_base, int32_t(nu_), int32_t(buckets_),
                     search_steps_, u + k0, column + k0, x + k0, redo);
    for (size_t k = 0; k < c; ++k)
      if (redo[k]) x[k0 + k] = sample_column(row[k0 + k], u[k0 + k], &column[k0 + k]);
  }
}

vec2 Distribution2D::sample(const vec2& u, float* pdf, glm::ivec2* cell) const {
  int row = 0, col = 0;
  const float v = sample_row(u.y, &row);
  const float x = sample_column(row, u.x, &col);
  if (pdf) *pdf = cell_pdf(col, row);
  if (cell) *cell = glm::ivec2(col, row);
  return vec2(x, v);
}

float Distribution2D::pdf(const vec2& p) const {
  return cell_pdf(cell_of(p.x, nu_), cell_of(p.y, nv_));
}

}  // namespace penumbra
