#pragma once
// The sampler's values for many (sample, dimension) pairs at once, for the wavefront driver: a
// bounce of a batch of paths needs the same few dimensions of every live path, and each value is
// a chain of some sixty dependent integer operations, which one path at a time leaves the CPU
// waiting on. Over arrays the same operations run in SIMD lanes (eight or sixteen entries per
// instruction where the CPU has AVX2 or AVX-512, chosen at run time). The values are those of
// Sampler::get_1d/get_2d to the bit: integer operations and an exact conversion.
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

// The values a step of many paths will take, computed together, and each path's view of them.
// Entry block k holds path k's next per_path dimensions (a bounce takes at most five: light
// choice, light point, lobe, direction, Russian roulette; the camera one to three); a path that
// takes more than were prefetched falls back to its sampler.
class BounceSamples {
 public:
  static constexpr int kBounce = 5;
  // A bounce without a next-event estimate (no light the integrator samples): lobe,
  // direction, Russian roulette.
  static constexpr int kBounceWithoutLight = 3;

  // Room for `paths` paths' values, per_path each, from path 0.
  void start(size_t paths, int per_path = kBounce) {
    per_path_ = per_path;
    const size_t n = paths * size_t(per_path);
    if (index_.size() < n) {
      index_.resize(n);
      seed_index_.resize(n);
      seed_x_.resize(n);
      seed_y_.resize(n);
      x_.resize(n);
      y_.resize(n);
    }
    paths_ = 0;
  }
  // Queues the next path's next per_path dimensions: `sampler` on the path's pixel, at `cursor`.
  void add(Sampler& sampler, const Sampler::Cursor& cursor) {
    const size_t e = paths_++ * size_t(per_path_);
    for (int j = 0; j < per_path_; ++j) index_[e + j] = cursor.index;
    if (per_path_ == kBounce)
      sampler.scrambles<kBounce>(cursor.dimension, &seed_index_[e], &seed_x_[e], &seed_y_[e]);
    else if (per_path_ == kBounceWithoutLight)
      sampler.scrambles<kBounceWithoutLight>(cursor.dimension, &seed_index_[e], &seed_x_[e], &seed_y_[e]);
    else
      sampler.scrambles(cursor.dimension, per_path_, &seed_index_[e], &seed_x_[e], &seed_y_[e]);
  }
  // Computes every queued value.
  void compute() {
    scrambled_sobol_batch(paths_ * size_t(per_path_), index_.data(), seed_index_.data(), seed_x_.data(),
                          seed_y_.data(), x_.data(), y_.data());
  }
  const float* x(size_t path) const { return x_.data() + path * size_t(per_path_); }
  const float* y(size_t path) const { return y_.data() + path * size_t(per_path_); }
  int per_path() const { return per_path_; }

 private:
  int per_path_ = kBounce;
  size_t paths_ = 0;
  std::vector<uint32_t> index_, seed_index_, seed_x_, seed_y_;
  std::vector<float> x_, y_;
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
        count_(samples.per_path()) {}

  // The prefetched values inline, the rare rest out of line: inlined whole, the fallback's
  // sampler code made GCC call these from the bounce step instead.
  [[gnu::always_inline]] float get_1d() {
    if (used_ < count_) {
      ++cursor_.dimension;
      return x_[used_++];
    }
    return fallback_1d();
  }
  [[gnu::always_inline]] vec2 get_2d() {
    if (used_ < count_) {
      ++cursor_.dimension;
      const int j = used_++;
      return vec2(x_[j], y_[j]);
    }
    return fallback_2d();
  }
  Sampler::Cursor cursor() const { return cursor_; }

 private:
  [[gnu::noinline]] float fallback_1d() {
    sampler_.resume(cursor_);
    const float u = sampler_.get_1d();
    cursor_ = sampler_.cursor();
    return u;
  }
  [[gnu::noinline]] vec2 fallback_2d() {
    sampler_.resume(cursor_);
    const vec2 u = sampler_.get_2d();
    cursor_ = sampler_.cursor();
    return u;
  }

  Sampler& sampler_;
  Sampler::Cursor cursor_;
  const float* x_;
  const float* y_;
  int count_;
  int used_ = 0;
};

}  // namespace penumbra
