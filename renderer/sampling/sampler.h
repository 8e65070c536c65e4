#pragma once
// Owen-scrambled Sobol sampler, padded in 2D pairs (Burley 2020, "Practical Hash-based Owen
// Scrambling", JCGT 9(4)). Every value is a pure function of (seed, pixel, sample index,
// dimension), so images do not depend on threads, tiles or the order samples are taken in.
#include <cstdint>

#include "renderer/core/math.h"

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
// The same, a byte at a time: the generator matrix is linear over GF(2), so the image of each
// index byte is looked up in a 4 x 256 table and the four parts XORed (scrambled indices use all
// 32 bits, which made the bit loop the sampler's main cost).
struct SobolDimension1Table {
  uint32_t entries[4][256];
  SobolDimension1Table() {
    for (int k = 0; k < 4; ++k)
      for (uint32_t b = 0; b < 256; ++b) entries[k][b] = sobol_dimension1_reference(b << (8 * k));
  }
};
inline uint32_t sobol_dimension1(uint32_t index) {
  static const SobolDimension1Table table;
  return table.entries[0][index & 0xffu] ^ table.entries[1][(index >> 8) & 0xffu] ^
         table.entries[2][(index >> 16) & 0xffu] ^ table.entries[3][index >> 24];
}

inline float fixed_to_unit_float(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

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
  explicit Sampler(uint64_t seed) : seed_(mix64(seed + 0x51ed270b27c3a4f1ull)) {}

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
  void resume(const Cursor& c) {
    index_ = c.index;
    dimension_ = c.dimension;
  }

  float get_1d() {
    const DimensionSeeds& h = seeds(dimension_++);
    const uint32_t shuffled = nested_uniform_scramble(index_, uint32_t(h.a));
    // nested_uniform_scramble(reverse(i)) = reverse(LK(i)): two reversals cancel.
    return fixed_to_unit_float(reverse_bits32(laine_karras_permutation(shuffled, uint32_t(h.a >> 32))));
  }

  vec2 get_2d() {
    const DimensionSeeds& h = seeds(dimension_++);
    const uint32_t shuffled = nested_uniform_scramble(index_, uint32_t(h.a));
    return vec2(
        fixed_to_unit_float(reverse_bits32(laine_karras_permutation(shuffled, uint32_t(h.a >> 32)))),
        fixed_to_unit_float(nested_uniform_scramble(sobol_dimension1(shuffled), uint32_t(h.b))));
  }

 private:
  struct DimensionSeeds {
    uint64_t a, b;
  };
  static constexpr uint64_t kCachedDimensions = SamplerDimensionKeys::kCount;

  const DimensionSeeds& seeds(uint64_t dimension) {
    if (dimension < kCachedDimensions) {
      DimensionSeeds& s = cache_[dimension];
      if (!((cached_ >> dimension) & 1u)) {
        s.a = mix64(pixel_seed_ ^ kSamplerDimensionKeys.key[dimension]);  // = hash_combine(pixel_seed_, dimension)
        s.b = mix64(s.a);
        cached_ |= uint64_t(1) << dimension;
      }
      return s;
    }
    overflow_.a = hash_combine(pixel_seed_, dimension);
    overflow_.b = mix64(overflow_.a);
    return overflow_;
  }

  uint64_t seed_;
  uint64_t pixel_seed_ = 0;
  int pixel_x_ = -1, pixel_y_ = -1;
  uint32_t index_ = 0;
  uint64_t dimension_ = 0;
  uint64_t cached_ = 0;  // bit d set: cache_[d] holds the seeds of dimension d for this pixel
  DimensionSeeds cache_[kCachedDimensions];
  DimensionSeeds overflow_{};
};

}  // namespace penumbra
