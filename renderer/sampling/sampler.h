#pragma once
// Owen-scrambled Sobol sampler, padded in 2D pairs (Burley 2020, "Practical Hash-based Owen
// Scrambling", JCGT 9(4)); a 1D value that goes with the 2D value after it (a light choice with
// its light point, a BSDF's lobe choice with its direction) is taken as one 3D point instead
// (get_1d_2d). A render of a sample count known in advance may take Kensler's correlated
// multi-jittered points instead (cmj.h) with the same seeds. Every value is a pure function of
// (seed, pattern, pixel, sample index, dimension), so images do not depend on threads, tiles or
// the order samples are taken in.
#include <array>
#include <cstdint>
#include <cstring>

#include "renderer/core/math.h"
#include "renderer/sampling/cmj.h"

namespace penumbra {

inline uint32_t reverse_bits32(uint32_t x) {
  x = ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);
  x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu);
  x = ((x & 0x00ff00ffu) << 8) | ((x >> 8) & 0x00ff00ffu);
  return (x << 16) | (x >> 16);
}

// 64-bit finaliser of SplitMix64 (Steele et al. 2014); used to derive independent seeds.
constexpr uint64_t mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}
inline constexpr uint64_t kGoldenGamma = 0x9e3779b97f4a7c15ull;
inline uint64_t hash_combine(uint64_t a, uint64_t b) { return mix64(a ^ (mix64(b) + kGoldenGamma)); }

// Laine-Karras style permutation (only lower bits influence higher ones), with the constants
// proposed by N. Vegdahl (2021) as an improvement on Burley's. Applied to bit-reversed values it
// is a nested uniform (Owen) scramble.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits32(laine_karras_permutation(reverse_bits32(x), seed));
}

// First two Sobol dimensions, as 0.32 fixed point. Dimension 0 is van der Corput; dimension 1
// uses the direction numbers of the primitive polynomial x + 1 (v_{k+1} = v_k ^ (v_k >> 1)).
inline uint32_t sobol_dimension0(uint32_t index) { return reverse_bits32(index); }
inline uint32_t sobol_dimension1_reference(uint32_t index) {
  uint32_t result = 0;
  for (uint32_t v = 1u << 31; index; index >>= 1, v ^= v >> 1)
    if (index & 1u) result ^= v;
  return result;
}
// The same without a loop. Column k of this dimension's generator matrix is row k of Pascal's
// triangle mod 2 read from the top bit (the recurrence is Pascal's rule), so output bit 31 - j is
// the parity of the index bits k with C(k, j) odd, which by Lucas' theorem are the k whose bits
// contain j's. That parity for all j at once is the superset-sum transform over GF(2): five
// shift-and-XOR steps, one per bit of j. So the dimension is a bit reversal of that transform,
// and a scramble applied in reversed order cancels the reversal (scrambled_sobol_y).
inline uint32_t superset_parity(uint32_t x) {
  x ^= (x >> 1) & 0x55555555u;
  x ^= (x >> 2) & 0x33333333u;
  x ^= (x >> 4) & 0x0f0f0f0fu;
  x ^= (x >> 8) & 0x00ff00ffu;
  x ^= (x >> 16) & 0x0000ffffu;
  return x;
}
inline uint32_t sobol_dimension1(uint32_t index) { return reverse_bits32(superset_parity(index)); }

// Sobol's third dimension, as 0.32 fixed point: primitive polynomial x^2 + x + 1 with initial
// direction numbers m = 1, 3 (Joe and Kuo 2008, their dimension 3), m_k = 2 m_{k-1} ^ 4 m_{k-2}
// ^ m_{k-2}; column k of the generator matrix is m_{k+1} / 2^{k+1}. Branch-free over the index's
// bits so that the batch kernel vectorises it.
inline constexpr std::array<uint32_t, 32> kSobolDimension2Columns = [] {
  std::array<uint32_t, 32> columns{};
  uint64_t m[33] = {0, 1, 3};
  for (int k = 3; k <= 32; ++k) m[k] = (2 * m[k - 1]) ^ (4 * m[k - 2]) ^ m[k - 2];
  for (int k = 1; k <= 32; ++k) columns[size_t(k - 1)] = uint32_t(m[k] << (32 - k));
  return columns;
}();
inline uint32_t sobol_dimension2(uint32_t index) {
  uint32_t result = 0;
  for (int k = 0; k < 32; ++k) result ^= kSobolDimension2Columns[size_t(k)] & (0u - ((index >> k) & 1u));
  return result;
}

// The top 24 bits as a float in [0, 1). x >> 8 < 2^24 converts exactly; through int32, so that
// vector code can use the signed conversion (SSE2 and AVX2 have no unsigned one).
inline float fixed_to_unit_float(uint32_t x) { return float(int32_t(x >> 8)) * 0x1p-24f; }

// The scrambling seeds of one (pixel, dimension): the sample index's shuffle and the two
// coordinates' scrambles.
struct DimensionScramble {
  uint32_t index, x, y;
};

// One scrambled Sobol point of a dimension pair: the sample index is shuffled by a nested uniform
// scramble (Burley 2020, section 4), then both coordinates are scrambled. Shared by
// Sampler::get_1d/get_2d and the batch kernel (sobol_batch.h), which must agree to the bit.
inline uint32_t shuffled_sample_index(uint32_t index, uint32_t seed) {
  return nested_uniform_scramble(index, seed);
}
inline float scrambled_sobol_x(uint32_t shuffled, uint32_t seed) {
  // nested_uniform_scramble(reverse(i)) = reverse(LK(i)): two reversals cancel.
  return fixed_to_unit_float(reverse_bits32(laine_karras_permutation(shuffled, seed)));
}
inline float scrambled_sobol_y(uint32_t shuffled, uint32_t seed) {
  // nested_uniform_scramble(sobol_dimension1(i)) = reverse(LK(superset_parity(i))).
  return fixed_to_unit_float(reverse_bits32(laine_karras_permutation(superset_parity(shuffled), seed)));
}
// The third coordinate of the same point, scrambled by its own seed.
inline float scrambled_sobol_z(uint32_t shuffled, uint32_t seed) {
  return fixed_to_unit_float(nested_uniform_scramble(sobol_dimension2(shuffled), seed));
}

// hash_combine(seed, d)'s hash of d for the dimensions the sampler caches: one of its two mixes,
// done at compile time (each pixel's first sample of a pass hashes every dimension it uses).
struct SamplerDimensionKeys {
  static constexpr uint64_t kCount = 64;
  uint64_t key[kCount];
  constexpr SamplerDimensionKeys() : key() {
    for (uint64_t d = 0; d < kCount; ++d) key[d] = mix64(d) + kGoldenGamma;
  }
};
inline constexpr SamplerDimensionKeys kSamplerDimensionKeys{};

class Sampler {
 public:
  // cmj_bits: 0 for the Owen-scrambled Sobol points; k for correlated multi-jittered points of
  // 2^k samples per pixel (cmj_bits_for), whose sample indices must stay below 2^k.
  explicit Sampler(uint64_t seed, uint32_t cmj_bits = 0)
      : seed_(mix64(seed + 0x51ed270b27c3a4f1ull)), cmj_bits_(cmj_bits) {}
  uint32_t cmj_bits() const { return cmj_bits_; }

  void start_pixel_sample(int x, int y, uint32_t sample_index) {
    // The scrambling seeds depend on (pixel, dimension) only, so consecutive samples of one
    // pixel reuse them.
    if (x != pixel_x_ || y != pixel_y_ || cached_ == 0) {
      pixel_x_ = x;
      pixel_y_ = y;
      pixel_seed_ = hash_combine(seed_, (uint64_t(uint32_t(y)) << 32) | uint32_t(x));
      cached_ = 0;
    }
    index_ = sample_index;
    dimension_ = 0;
  }

  // Where a sample is in its dimensions. The wavefront integrator interleaves the paths of one
  // pixel's samples on one sampler (the dimension seeds depend on the pixel alone): it sets a
  // path's cursor aside between bounces and resumes it, with the sampler still on that pixel.
  struct Cursor {
    uint32_t index;
    uint64_t dimension;
  };
  Cursor cursor() const { return Cursor{index_, dimension_}; }
  // What the scrambling seeds depend on besides the dimension: the seed and the pixel.
  uint64_t pixel_key() const { return pixel_seed_; }
  void resume(const Cursor& c) {
    index_ = c.index;
    dimension_ = c.dimension;
  }

  float get_1d() {
    const DimensionScramble h = scramble(dimension_++);
    if (cmj_bits_) return fixed_to_unit_float(cmj_x(cmj_cell(index_, cmj_bits_, h.index), cmj_bits_, h.x));
    return scrambled_sobol_x(shuffled_sample_index(index_, h.index), h.x);
  }

  vec2 get_2d() {
    const DimensionScramble h = scramble(dimension_++);
    if (cmj_bits_) {
      uint32_t cell;
      return cmj_2d(h, &cell);
    }
    const uint32_t shuffled = shuffled_sample_index(index_, h.index);
    return vec2(scrambled_sobol_x(shuffled, h.x), scrambled_sobol_y(shuffled, h.y));
  }

  // A 1D value and the 2D value that goes with it (dimensions d and d + 1) as one Owen-scrambled
  // 3D point: Sobol dimensions 0 and 1 of dimension d + 1's shuffled index are the 2D value
  // (get_2d's at d + 1, unchanged), Sobol dimension 2 of the same index, scrambled by dimension
  // d's seed, the 1D value. Each value is still uniform and the pairs still padded against
  // every other dimension, but the first 2^m samples of a pixel are now a net in the three
  // together (8 x 8 x 4 boxes of 256 samples hold one each): the lobe a BSDF picks is stratified
  // jointly with the direction it samples in that lobe, the light chosen with the point on it.
  // Measured (docs/performance.md, levers, session 22): at 256 spp 0.81 of the variance on
  // plastics, 0.92 on furnace, 0.84 on all_lights; 0.96-1.00 elsewhere.
  // With CMJ points the 2D value is get_2d's at d + 1 and the 1D value is stratified jointly with
  // it by cmj_z.
  void get_1d_2d(float* u1, vec2* u2) {
    const DimensionScramble h1 = scramble(dimension_++);
    const DimensionScramble h2 = scramble(dimension_++);
    if (cmj_bits_) {
      uint32_t cell;
      *u2 = cmj_2d(h2, &cell);
      *u1 = fixed_to_unit_float(cmj_z(cell, cmj_bits_, h1.x));
      return;
    }
    const uint32_t shuffled = shuffled_sample_index(index_, h2.index);
    *u2 = vec2(scrambled_sobol_x(shuffled, h2.x), scrambled_sobol_y(shuffled, h2.y));
    *u1 = scrambled_sobol_z(shuffled, h1.x);
  }

  // The seeds of a dimension of the current pixel (the batch kernel takes them from here).
  DimensionScramble scramble(uint64_t dimension) {
    if (dimension < kCachedDimensions) {
      fill_cache(dimension);
      return DimensionScramble{cache_index_[dimension], cache_x_[dimension], cache_y_[dimension]};
    }
    return scramble_of(hash_combine(pixel_seed_, dimension));
  }
  // Those of `count` consecutive dimensions from `first`, as three arrays.
  void scrambles(uint64_t first, int count, uint32_t* index, uint32_t* x, uint32_t* y) {
    for (int j = 0; j < count; ++j) {
      const DimensionScramble h = scramble(first + uint64_t(j));
      index[j] = h.index;
      x[j] = h.x;
      y[j] = h.y;
    }
  }
  // The same for a count known at compile time (a bounce's): a run already cached is copied in
  // a few moves.
  template <int count>
  void scrambles(uint64_t first, uint32_t* index, uint32_t* x, uint32_t* y) {
    static_assert(count > 0 && count < int(kCachedDimensions));
    constexpr uint64_t kBlock = (uint64_t(1) << count) - 1;
    if (first + count <= kCachedDimensions && ((cached_ >> first) & kBlock) == kBlock) {
      std::memcpy(index, &cache_index_[first], sizeof(uint32_t) * count);
      std::memcpy(x, &cache_x_[first], sizeof(uint32_t) * count);
      std::memcpy(y, &cache_y_[first], sizeof(uint32_t) * count);
      return;
    }
    scrambles(first, count, index, x, y);
  }

 private:
  static constexpr uint64_t kCachedDimensions = SamplerDimensionKeys::kCount;

  // The correlated multi-jittered 2D point of the current sample in the dimension scrambled by h,
  // and its cell (which a get_1d_2d pair's 1D value is stratified with: cmj_z).
  vec2 cmj_2d(const DimensionScramble& h, uint32_t* cell) const {
    *cell = cmj_cell(index_, cmj_bits_, h.index);
    return vec2(fixed_to_unit_float(cmj_x(*cell, cmj_bits_, h.x)),
                fixed_to_unit_float(cmj_y(*cell, cmj_bits_, h.y)));
  }

  // A dimension's 64-bit hash a gives the index shuffle (low half) and the first coordinate's
  // scramble (high half); mix64(a) the second's.
  static DimensionScramble scramble_of(uint64_t a) {
    return DimensionScramble{uint32_t(a), uint32_t(a >> 32), uint32_t(mix64(a))};
  }
  void fill_cache(uint64_t dimension) {
    if ((cached_ >> dimension) & 1u) return;
    // = hash_combine(pixel_seed_, dimension)
    const DimensionScramble h = scramble_of(mix64(pixel_seed_ ^ kSamplerDimensionKeys.key[dimension]));
    cache_index_[dimension] = h.index;
    cache_x_[dimension] = h.x;
    cache_y_[dimension] = h.y;
    cached_ |= uint64_t(1) << dimension;
  }

  uint64_t seed_;
  uint32_t cmj_bits_;
  uint64_t pixel_seed_ = 0;
  int pixel_x_ = -1, pixel_y_ = -1;
  uint32_t index_ = 0;
  uint64_t dimension_ = 0;
  uint64_t cached_ = 0;  // bit d set: cache_[d] holds the seeds of dimension d for this pixel
  // The cached dimensions' seeds, by part (the batch kernel copies runs of them).
  uint32_t cache_index_[kCachedDimensions], cache_x_[kCachedDimensions], cache_y_[kCachedDimensions];
};

}  // namespace penumbra
