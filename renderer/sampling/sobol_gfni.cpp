#include "renderer/sampling/sobol_gfni.h"

#include <array>
#include <cstdlib>

#include "renderer/sampling/sampler.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define PENUMBRA_SOBOL_GFNI 1
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_epi32() as the unused merge source, which it
// then reports as uninitialised at every inlined call (GCC bug 105593, fixed in GCC 13).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#endif

namespace penumbra {

#ifdef PENUMBRA_SOBOL_GFNI

namespace {

// A 32 x 32 GF(2) matrix as the 8 x 8 blocks that GFNI's affine step applies (Intel SDM,
// GF2P8AFFINEQB: result bit b of a byte is the parity of the byte AND matrix byte 7 - b). Block
// (i, j) maps input byte i to its share of output byte j; blocks that are zero are left out (the
// Sobol matrices are triangular: 10 of 16 remain).
struct ByteBlocks {
  struct Block {
    int in, out;
    uint64_t matrix;
  };
  std::array<Block, 16> block{};
  int count = 0;
};

// column[k]: the image of input bit k.
constexpr ByteBlocks byte_blocks(const std::array<uint32_t, 32>& column) {
  ByteBlocks blocks;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      uint64_t matrix = 0;
      for (int b = 0; b < 8; ++b) {
        uint64_t row = 0;  // which bits a of input byte i reach output bit 8 j + b
        for (int a = 0; a < 8; ++a) row |= uint64_t((column[size_t(8 * i + a)] >> (8 * j + b)) & 1u) << a;
        matrix |= row << (8 * (7 - b));
      }
      if (matrix != 0) blocks.block[size_t(blocks.count++)] = {i, j, matrix};
    }
  return blocks;
}

constexpr uint32_t reverse_bits32_constexpr(uint32_t x) {
  uint32_t r = 0;
  for (int k = 0; k < 32; ++k) r |= ((x >> k) & 1u) << (31 - k);
  return r;
}

// The third dimension between the index shuffle's last reversal and the scramble's first:
// u -> reverse(sobol_dimension2(reverse(u))), so that neither reversal is computed.
constexpr std::array<uint32_t, 32> reversed_dimension2_columns() {
  std::array<uint32_t, 32> column{};
  for (int k = 0; k < 32; ++k) column[size_t(k)] = reverse_bits32_constexpr(kSobolDimension2Columns[size_t(31 - k)]);
  return column;
}
constexpr ByteBlocks kReversedDimension2 = byte_blocks(reversed_dimension2_columns());

#define PENUMBRA_GFNI_TARGET __attribute__((target("avx512f,avx512bw,gfni")))

// Each byte's bits reversed (the anti-diagonal 8 x 8 matrix), then the bytes of each 32-bit lane.
PENUMBRA_GFNI_TARGET inline __m512i reverse_lanes(__m512i x) {
  const __m512i bits = _mm512_gf2p8affine_epi64_epi8(x, _mm512_set1_epi64(0x8040201008040201ll), 0);
  const __m512i bytes = _mm512_broadcast_i32x4(_mm_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12));
  return _mm512_shuffle_epi8(bits, bytes);
}

// laine_karras_permutation, lane by lane.
PENUMBRA_GFNI_TARGET inline __m512i laine_karras_lanes(__m512i x, __m512i seed) {
  x = _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32(0x3d20adea)));
  x = _mm512_add_epi32(x, seed);
  x = _mm512_mullo_epi32(x, _mm512_or_si512(_mm512_srli_epi32(seed, 16), _mm512_set1_epi32(1)));
  x = _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32(0x05526c56)));
  x = _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32(0x53a22864)));
  return x;
}

// superset_parity, lane by lane: x ^ ((x >> s) & mask) is one ternary-logic step (0x78: A ^ (B & C)).
PENUMBRA_GFNI_TARGET inline __m512i superset_parity_lanes(__m512i x) {
  x = _mm512_ternarylogic_epi32(x, _mm512_srli_epi32(x, 1), _mm512_set1_epi32(0x55555555), 0x78);
  x = _mm512_ternarylogic_epi32(x, _mm512_srli_epi32(x, 2), _mm512_set1_epi32(0x33333333), 0x78);
  x = _mm512_ternarylogic_epi32(x, _mm512_srli_epi32(x, 4), _mm512_set1_epi32(0x0f0f0f0f), 0x78);
  x = _mm512_ternarylogic_epi32(x, _mm512_srli_epi32(x, 8), _mm512_set1_epi32(0x00ff00ff), 0x78);
  return _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
}

// A matrix of ByteBlocks, lane by lane: input byte i copied to the lane's four bytes, each block's
// affine step kept in its output byte (a byte mask) and summed.
PENUMBRA_GFNI_TARGET inline __m512i apply_blocks(__m512i x, const ByteBlocks& blocks) {
  __m512i spread[4];
  // Byte i of every lane: shuffle indices i, i, i, i plus the lane's offset within its 128 bits.
  for (int i = 0; i < 4; ++i)
    spread[i] = _mm512_shuffle_epi8(
        x, _mm512_broadcast_i32x4(_mm_setr_epi8(char(i), char(i), char(i), char(i), char(4 + i), char(4 + i),
                                                char(4 + i), char(4 + i), char(8 + i), char(8 + i), char(8 + i),
                                                char(8 + i), char(12 + i), char(12 + i), char(12 + i), char(12 + i))));
  __m512i sum = _mm512_setzero_si512();
  constexpr __mmask64 kOutputByte[4] = {0x1111111111111111ull, 0x2222222222222222ull, 0x4444444444444444ull,
                                        0x8888888888888888ull};
#pragma GCC unroll 16
  for (int b = 0; b < 16; ++b) {
    if (b >= blocks.count) break;
    const ByteBlocks::Block& block = blocks.block[size_t(b)];
    sum = _mm512_xor_si512(sum, _mm512_maskz_gf2p8affine_epi64_epi8(kOutputByte[block.out], spread[block.in],
                                                                     _mm512_set1_epi64(int64_t(block.matrix)), 0));
  }
  return sum;
}

// fixed_to_unit_float, lane by lane (the same exact signed conversion).
PENUMBRA_GFNI_TARGET inline __m512 unit_float_lanes(__m512i x) {
  return _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_srli_epi32(x, 8)), _mm512_set1_ps(0x1p-24f));
}

// The lanes of entries i .. i + 15 that exist (the tail's under a mask).
inline __mmask16 live_lanes(size_t n, size_t i) {
  return n - i >= 16 ? __mmask16(0xffff) : __mmask16((1u << (n - i)) - 1u);
}

// The sample indices' shuffle before its last reversal: shuffled_sample_index is reverse(u).
PENUMBRA_GFNI_TARGET inline __m512i shuffle_before_reversal(__mmask16 live, const uint32_t* index,
                                                           const uint32_t* seed_index) {
  return laine_karras_lanes(reverse_lanes(_mm512_maskz_loadu_epi32(live, index)),
                            _mm512_maskz_loadu_epi32(live, seed_index));
}

}  // namespace

bool sobol_gfni_available() {
  static const bool available = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                                __builtin_cpu_supports("gfni");
  return available;
}

PENUMBRA_GFNI_TARGET void scrambled_sobol_batch_gfni(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                                     const uint32_t* seed_x, const uint32_t* seed_y, float* x,
                                                     float* y) {
  for (size_t i = 0; i < n; i += 16) {
    const __mmask16 live = live_lanes(n, i);
    const __m512i shuffled = reverse_lanes(shuffle_before_reversal(live, index + i, seed_index + i));
    const __m512i sx = _mm512_maskz_loadu_epi32(live, seed_x + i);
    const __m512i sy = _mm512_maskz_loadu_epi32(live, seed_y + i);
    _mm512_mask_storeu_ps(x + i, live, unit_float_lanes(reverse_lanes(laine_karras_lanes(shuffled, sx))));
    _mm512_mask_storeu_ps(y + i, live,
                          unit_float_lanes(reverse_lanes(laine_karras_lanes(superset_parity_lanes(shuffled), sy))));
  }
}

PENUMBRA_GFNI_TARGET void scrambled_sobol_z_batch_gfni(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                                       const uint32_t* seed_z, float* z) {
  for (size_t i = 0; i < n; i += 16) {
    const __mmask16 live = live_lanes(n, i);
    // reverse(sobol_dimension2(shuffled)) with shuffled = reverse(u): one matrix of u.
    const __m512i u = shuffle_before_reversal(live, index + i, seed_index + i);
    const __m512i reversed = apply_blocks(u, kReversedDimension2);
    const __m512i sz = _mm512_maskz_loadu_epi32(live, seed_z + i);
    _mm512_mask_storeu_ps(z + i, live, unit_float_lanes(reverse_lanes(laine_karras_lanes(reversed, sz))));
  }
}

#else

// Not an x86-64 GCC or Clang build: the portable kernels run, and these are never called.
bool sobol_gfni_available() { return false; }
void scrambled_sobol_batch_gfni(size_t, const uint32_t*, const uint32_t*, const uint32_t*, const uint32_t*, float*,
                                float*) {
  std::abort();
}
void scrambled_sobol_z_batch_gfni(size_t, const uint32_t*, const uint32_t*, const uint32_t*, float*) { std::abort(); }

#endif

}  // namespace penumbra
