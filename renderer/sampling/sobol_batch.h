#pragma once
// The sampler's values for many (sample, dimension) pairs at once, for the wavefront driver: a
// bounce of a batch of paths needs the same few dimensions of every live path, and each value is
// a chain of some sixty dependent integer operations, which one path at a time leaves the CPU
// waiting on. Over arrays the same operations run in SIMD lanes (eight or sixteen entries per
// instruction where the CPU has AVX2 or AVX-512, chosen at run time). The values are those of
// Sampler::get_1d/get_2d/get_1d_2d to the bit: integer operations and an exact conversion.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "renderer/sampling/sampler.h"

namespace penumbra {

// Entry i: get_2d() of sample `index[i]` in a dimension with seeds (seed_index[i], seed_x[i],
// seed_y[i]) (a DimensionScramble; get_1d() is its x). Arrays of n entries; x and y must not
// alias the inputs.
void scrambled_sobol_batch(size_t n, const uint32_t* index, const uint32_t* seed_index,
                           const uint32_t* seed_x, const uint32_t* seed_y, float* x, float* y);
// Entry i: the 1D value of Sampler::get_1d_2d whose 2D value has seeds (seed_index[i], ...) and
// whose own dimension has x seed seed_z[i] (scrambled_sobol_z of the shared shuffled index).
void scrambled_sobol_z_batch(size_t n, const uint32_t* index, const uint32_t* seed_index,
                             const uint32_t* seed_z, float* z);
// The two run sobol_gfni.h's kernels where the CPU has them, else these: loops that GCC
// compiles for baseline x86-64, AVX2 and AVX-512 (the same values; named for the tests).
void scrambled_sobol_batch_portable(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                    const uint32_t* seed_x, const uint32_t* seed_y, float* x, float* y);
void scrambled_sobol_z_batch_portable(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                      const uint32_t* seed_z, float* z);

// The same values for correlated multi-jittered points of 2^bits samples (Sampler with
// cmj_bits = bits; cmj.h), in three steps that share each entry's cell (cmj_cell): the cells and
// the x values (get_1d's, get_2d's x); the y values from the cells; the 1D values of get_1d_2d
// pairs from the cells of their 2D dimension. Loops that GCC compiles for baseline x86-64, AVX2
// and AVX-512.
void cmj_cells_x_batch(size_t n, uint32_t bits, const uint32_t* index, const uint32_t* seed_index,
                       const uint32_t* seed_x, uint32_t* cell, float* x);
void cmj_y_batch(size_t n, uint32_t bits, const uint32_t* cell, const uint32_t* seed_y, float* y);
// (cmj_z_batch takes each entry's seed_rows[i] = cmj_z_rows_seed(seed_z[i]), which is the same
// for a run of one pixel's samples.)
void cmj_z_batch(size_t n, uint32_t bits, const uint32_t* cell, const uint32_t* seed_z,
                 const uint32_t* seed_rows, float* z);

// How many pairs start below dimension j: the bits of `pairs` under bit j. Shifts and adds
// rather than std::popcount, which a baseline x86-64 build (no POPCNT) makes a call into
// libgcc -- on every prefetched 1D-2D pair, about 1% of a mesh scene's samples.
[[gnu::always_inline]] inline int pairs_below(uint32_t pairs, int j) {
  uint32_t v = pairs & ((uint32_t(1) << j) - 1u);
  v = v - ((v >> 1) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
  return int((((v + (v >> 4)) & 0x0F0F0F0Fu) * 0x01010101u) >> 24);
}

// The values a step of many paths will take, computed together, and each path's view of them.
// Path k's next per_path dimensions (a bounce takes at most five: light choice, light point,
// lobe, direction, Russian roulette; the camera one to three) are entries k, k + stride, ...,
// k + (per_path - 1) stride: dimension-major, so that each dimension's values for all paths are
// one kernel call over contiguous arrays. A path that takes more than were prefetched falls back
// to its sampler.
//
// The scrambling seeds depend on the pixel and the dimension alone, and consecutive paths of a
// batch are mostly one pixel's samples at one depth: a run of paths on the same pixel (of the
// same seed: Sampler::pixel_key) at the same dimension takes its seeds from the sampler once
// (`add` starts a run when either changes), and `compute` spreads them over the run's entries
// before the kernels.
class BounceSamples {
 public:
  static constexpr int kBounce = 5;
  // A bounce without a next-event estimate (no light the integrator samples): lobe,
  // direction, Russian roulette.
  static constexpr int kBounceWithoutLight = 3;

  // The dimensions where a bounce's get_1d_2d pairs start (bit j: dimensions j and j + 1):
  // light choice with light point, lobe with direction; without a light, lobe with direction.
  // A surface that estimates no light (all lobes Dirac) takes its lobe and direction at
  // dimensions 0 and 1 of a bounce with lights: the same pair.
  static constexpr uint32_t kBouncePairs = 0b00101u, kBounceWithoutLightPairs = 0b001u;
  // The dimensions a bounce reads as 2D values (the pairs' second dimensions: light point,
  // direction); the others are 1D values or the 1D halves of pairs.
  static constexpr uint32_t kBounceTwoD = 0b01010u, kBounceWithoutLightTwoD = 0b010u;

  // Room for `paths` paths' values, per_path each, from path 0. `pairs`: where get_1d_2d pairs
  // start; `computed`: those of them whose 1D values are computed here too (z; a pair whose 1D
  // value nobody reads, the light choice with one light or the lobe of single-lobe surfaces,
  // need not be), besides every dimension's get_1d values and, for the dimensions of `two_d`
  // (and the pairs' second ones), their get_2d values. A path reading a 2D value elsewhere takes
  // it from its sampler (PrefetchedSampler): the second coordinate of a correlated
  // multi-jittered point costs about what the first does, and a bounce reads two of five.
  // `unread_x`: dimensions whose get_1d value the caller's stages do not read (CMJ points leave
  // their cells and x out; a path that asks for one anyway gets it from its sampler,
  // PrefetchedSampler); dimensions whose 2D value is computed, or whose cells a pair's 1D value
  // takes, keep theirs.
  void start(size_t paths, int per_path = kBounce, uint32_t pairs = 0, uint32_t computed = 0,
             uint32_t two_d = ~0u, uint32_t unread_x = 0u) {
    per_path_ = per_path;
    stride_ = paths;
    // A pair needs its 2D dimension among the prefetched ones.
    pairs_ = per_path > 1 ? pairs & ((uint32_t(1) << (per_path - 1)) - 1u) : 0u;
    computed_ = computed & pairs_;
    two_d_ = two_d | (pairs_ << 1);
    unread_x_ = unread_x & ~two_d_;
    const size_t nz = paths * size_t(std::popcount(pairs_));
    if (z_seed_index_.size() < nz) {
      z_seed_index_.resize(nz);
      z_seed_rows_.resize(nz);
      z_seed_.resize(nz);
      z_.resize(nz);
    }
    if (path_index_.size() < paths) path_index_.resize(paths);
    const size_t n = paths * size_t(per_path);
    if (seed_index_.size() < n) {
      seed_index_.resize(n);
      seed_x_.resize(n);
      seed_y_.resize(n);
      x_.resize(n);
      y_.resize(n);
      cell_.resize(n);
    }
    paths_ = 0;
    cmj_bits_ = 0;
    runs_.clear();
    run_seed_index_.clear();
    run_seed_x_.clear();
    run_seed_y_.clear();
  }
  // Queues the next path's next per_path dimensions: `sampler` on the path's pixel, at `cursor`.
  void add(Sampler& sampler, const Sampler::Cursor& cursor) {
    add_run(sampler, cursor.index, 1, cursor.dimension);
  }
  // Queues `count` paths of one pixel at once: samples first, first + 1, ... of `sampler`'s
  // pixel, each at `dimension` (a camera stage's run of one pixel's samples; the same values as
  // `count` calls of add).
  void add_run(Sampler& sampler, uint32_t first, size_t count, uint64_t dimension) {
    if (count == 0) return;
    const size_t k = paths_;
    paths_ += count;
    for (size_t j = 0; j < count; ++j) path_index_[k + j] = first + uint32_t(j);
    if (!runs_.empty() && runs_.back().pixel == sampler.pixel_key() && runs_.back().dimension == dimension) {
      runs_.back().count += count;
      return;
    }
    start_run(sampler, dimension, k, count);
  }
  // Computes every queued value.
  void compute() {
    // Each run's seeds over its entries: dimension j's (x and y) and, for a computed pair
    // starting at j, its 2D dimension's index shuffle and its own dimension's x seed (z).
    const uint32_t one_d = this->one_d();
    for (size_t r = 0; r < runs_.size(); ++r) {
      const Run& run = runs_[r];
      const size_t seeds = r * size_t(per_path_);
      for (int j = 0; j < per_path_; ++j) {
        if (!((one_d >> j) & 1u)) continue;
        const size_t e = size_t(j) * stride_ + run.first;
        std::fill_n(seed_index_.data() + e, run.count, run_seed_index_[seeds + size_t(j)]);
        std::fill_n(seed_x_.data() + e, run.count, run_seed_x_[seeds + size_t(j)]);
        std::fill_n(seed_y_.data() + e, run.count, run_seed_y_[seeds + size_t(j)]);
      }
      for (uint32_t bits = computed_; bits; bits &= bits - 1) {
        const int j = std::countr_zero(bits);
        const size_t q = size_t(pair_index(j)) * stride_ + run.first;
        // (CMJ points take a pair's 1D value from its 2D dimension's cells, not its shuffle.)
        const uint32_t seed_z = run_seed_x_[seeds + size_t(j)];
        if (cmj_bits_)
          std::fill_n(z_seed_rows_.data() + q, run.count, cmj_z_rows_seed(seed_z));
        else
          std::fill_n(z_seed_index_.data() + q, run.count, run_seed_index_[seeds + size_t(j) + 1]);
        std::fill_n(z_seed_.data() + q, run.count, seed_z);
      }
    }
    // data() + e, not &v[e]: a step with no paths has empty vectors (e = 0).
    if (cmj_bits_) {
      for (int j = 0; j < per_path_; ++j) {
        if (!((one_d >> j) & 1u)) continue;
        const size_t e = size_t(j) * stride_;
        cmj_cells_x_batch(paths_, cmj_bits_, path_index_.data(), seed_index_.data() + e, seed_x_.data() + e,
                          cell_.data() + e, x_.data() + e);
        if ((two_d_ >> j) & 1u) cmj_y_batch(paths_, cmj_bits_, cell_.data() + e, seed_y_.data() + e, y_.data() + e);
      }
      // A pair's 1D value from its 2D dimension's cells.
      for (uint32_t bits = computed_; bits; bits &= bits - 1) {
        const int j = std::countr_zero(bits);
        const size_t q = size_t(pair_index(j)) * stride_;
        cmj_z_batch(paths_, cmj_bits_, cell_.data() + size_t(j + 1) * stride_, z_seed_.data() + q,
                    z_seed_rows_.data() + q, z_.data() + q);
      }
      return;
    }
    for (int j = 0; j < per_path_; ++j) {
      const size_t e = size_t(j) * stride_;
      scrambled_sobol_batch(paths_, path_index_.data(), seed_index_.data() + e, seed_x_.data() + e,
                            seed_y_.data() + e, x_.data() + e, y_.data() + e);
    }
    for (uint32_t bits = computed_; bits; bits &= bits - 1) {
      const size_t q = size_t(pair_index(std::countr_zero(bits))) * stride_;
      scrambled_sobol_z_batch(paths_, path_index_.data(), z_seed_index_.data() + q, z_seed_.data() + q,
                              z_.data() + q);
    }
  }
  // Path k's dimension j: x(k)[j * stride()] (its 1D value, or its 2D value's first
  // coordinate), y(k)[j * stride()]; its pairs' 1D values: pair i (the i-th of `pairs` from the
  // lowest dimension) at z(k)[i * stride()], a pair that was not computed holding a stale value.
  const float* x(size_t path) const { return x_.data() + path; }
  const float* y(size_t path) const { return y_.data() + path; }
  const float* z(size_t path) const { return z_.data() + path; }
  size_t stride() const { return stride_; }
  // Dimension j's values for all paths, contiguous: x(k)[j * stride()] is dimension_x(j)[k].
  const float* dimension_x(int j) const { return x_.data() + size_t(j) * stride_; }
  const float* dimension_y(int j) const { return y_.data() + size_t(j) * stride_; }
  int per_path() const { return per_path_; }
  uint32_t pairs() const { return pairs_; }
  // The dimensions whose 2D values were computed (Sobol points: all of them).
  uint32_t two_d() const { return cmj_bits_ ? two_d_ : ~0u; }
  // The dimensions whose x (get_1d) values were computed: with CMJ points all but start's
  // `unread_x` (a bounce's light choice and lobe are read as their pairs' z where anyone reads
  // them, its roulette value only from depth rr_depth on: their cells and x would be up to three
  // of a bounce's five cell permutations, unread); with Sobol points all (its kernel makes x and
  // y together, and costs a fraction of CMJ's).
  uint32_t one_d() const { return cmj_bits_ ? ~unread_x_ : ~0u; }
  uint32_t computed_pairs() const { return computed_; }
  // Which pair starts at dimension j (j a bit of pairs).
  int pair_index(int j) const { return pairs_below(pairs_, j); }

 private:
  // A new run from path k: its dimensions' seeds from the sampler, now (it may move to another
  // pixel before compute).
  void start_run(Sampler& sampler, uint64_t dimension, size_t k, size_t count) {
    cmj_bits_ = sampler.cmj_bits();  // one pattern per render: every sampler of a batch has it
    runs_.push_back(Run{sampler.pixel_key(), dimension, k, count});
    const size_t r = run_seed_index_.size();
    run_seed_index_.resize(r + size_t(per_path_));
    run_seed_x_.resize(r + size_t(per_path_));
    run_seed_y_.resize(r + size_t(per_path_));
    if (per_path_ == kBounce)
      sampler.scrambles<kBounce>(dimension, &run_seed_index_[r], &run_seed_x_[r], &run_seed_y_[r]);
    else if (per_path_ == kBounceWithoutLight)
      sampler.scrambles<kBounceWithoutLight>(dimension, &run_seed_index_[r], &run_seed_x_[r],
                                             &run_seed_y_[r]);
    else
      sampler.scrambles(dimension, per_path_, &run_seed_index_[r], &run_seed_x_[r], &run_seed_y_[r]);
  }
  struct Run {
    uint64_t pixel, dimension;  // Sampler::pixel_key(), and the run's first dimension
    size_t first, count;
  };
  int per_path_ = kBounce;
  uint32_t pairs_ = 0, computed_ = 0, two_d_ = ~0u, unread_x_ = 0, cmj_bits_ = 0;
  size_t paths_ = 0, stride_ = 0;
  std::vector<Run> runs_;
  std::vector<uint32_t> run_seed_index_, run_seed_x_, run_seed_y_;  // per_path per run
  std::vector<uint32_t> seed_index_, seed_x_, seed_y_;
  std::vector<float> x_, y_;
  std::vector<uint32_t> cell_;  // CMJ points: each entry's cell (cmj_cell)
  std::vector<uint32_t> path_index_, z_seed_index_, z_seed_, z_seed_rows_;
  std::vector<float> z_;
};

// One path's sampler during a bounce: the prefetched values first, then its own sampler (a
// drop-in for Sampler in path_hit).
class PrefetchedSampler {
 public:
  PrefetchedSampler(Sampler& sampler, const Sampler::Cursor& cursor, const BounceSamples& samples,
                    size_t path)
      : sampler_(sampler),
        cursor_(cursor),
        x_(samples.x(path)),
        y_(samples.y(path)),
        z_(samples.z(path)),
        stride_(samples.stride()),
        count_(samples.per_path()),
        pairs_(samples.pairs()),
        computed_(samples.computed_pairs()),
        two_d_(samples.two_d()),
        one_d_(samples.one_d()) {}

  // The prefetched values inline, the rare rest out of line: inlined whole, the fallback's
  // sampler code made GCC call these from the bounce step instead.
  [[gnu::always_inline]] float get_1d() {
    if (used_ < count_ && ((one_d_ >> used_) & 1u)) {
      ++cursor_.dimension;
      return x_[size_t(used_++) * stride_];
    }
    return fallback_1d();
  }
  [[gnu::always_inline]] vec2 get_2d() {
    if (used_ < count_ && ((two_d_ >> used_) & 1u)) {
      ++cursor_.dimension;
      const size_t e = size_t(used_++) * stride_;
      return vec2(x_[e], y_[e]);
    }
    return fallback_2d();
  }
  // Sampler::get_1d_2d: prefetched where a pair was computed to start here, else the sampler's.
  [[gnu::always_inline]] void get_1d_2d(float* u1, vec2* u2) {
    if (used_ < count_ && ((computed_ >> used_) & 1u)) {
      const int j = used_;
      *u1 = z_[size_t(pairs_below(pairs_, j)) * stride_];
      const size_t e = size_t(j + 1) * stride_;
      *u2 = vec2(x_[e], y_[e]);
      used_ += 2;
      cursor_.dimension += 2;
      return;
    }
    fallback_1d_2d(u1, u2);
  }
  Sampler::Cursor cursor() const { return cursor_; }

 private:
  [[gnu::noinline]] void fallback_1d_2d(float* u1, vec2* u2) {
    sampler_.resume(cursor_);
    sampler_.get_1d_2d(u1, u2);
    cursor_ = sampler_.cursor();
    used_ += 2;
  }
  [[gnu::noinline]] float fallback_1d() {
    sampler_.resume(cursor_);
    const float u = sampler_.get_1d();
    cursor_ = sampler_.cursor();
    ++used_;  // (a prefetched dimension whose x was not computed: the next stays aligned)
    return u;
  }
  [[gnu::noinline]] vec2 fallback_2d() {
    sampler_.resume(cursor_);
    const vec2 u = sampler_.get_2d();
    cursor_ = sampler_.cursor();
    ++used_;  // (a prefetched dimension whose 2D value was not computed: the next stays aligned)
    return u;
  }

  Sampler& sampler_;
  Sampler::Cursor cursor_;
  const float* x_;
  const float* y_;
  const float* z_;
  size_t stride_;
  int count_;
  uint32_t pairs_, computed_, two_d_, one_d_;
  int used_ = 0;
};

}  // namespace penumbra
