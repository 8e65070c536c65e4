#pragma once
// Correlated multi-jittered points (Kensler 2013, "Correlated Multi-Jittered Sampling", Pixar
// Technical Memo 13-01) for renders whose sample count per pixel is known before they start: a
// uniform render's N samples of a pixel are, per dimension pair, one sample in each cell of an
// m x n grid and one in each of the N columns and N rows of the fine grid (N-rooks), with the
// fine offsets shared along the coarse rows and columns (the "correlated" part, which keeps the
// points from clumping). Where a scene's error is in its indirect light this pattern has less
// variance at equal samples than the Owen-scrambled Sobol pairs of sampler.h (cornell: 0.93 at
// 64 spp; docs/performance.md, levers, session 38), but it is not progressive: its first k of N
// samples are not stratified among themselves, so adaptive sampling and time budgets keep the
// Sobol sampler, whose every power-of-two prefix is a net.
//
// Everything here is integer arithmetic on 0.32 fixed point, with N = 2^bits (2 <= N <= 2^24; a
// render of one sample takes the first of two): the batch kernels (sobol_batch.h) compute the
// same bits in SIMD lanes. A render of another count takes the Sobol points: the first spp of the
// next power of two's pattern have more variance than spp Sobol points (render.cpp).
#include <bit>
#include <cstdint>

namespace penumbra {

// A permutation of [0, 2^k) (mask = 2^k - 1), chosen by p. Each step is invertible on the low
// k bits: xor with a constant, multiplication by an odd number, xor with the masked value shifted
// down (which carries the high bits' randomness into the low ones). Three multiplications, one
// by a function of p, where Kensler's hash (section 3 of his memo) takes seven: the batch
// kernels compute several per value, and with this one correlated multi-jittered points cost
// 1-3% of a render more than the Sobol points (docs/performance.md, levers, session 38). For a
// fixed i the output is uniform over p (the last step adds p's bits 8 and up). Two
// permutations whose seeds are related (p and p ^ constant) are related too: seeds must be
// independent hashes (a chi-square test caught a lobe value tied to the cell it went with).
inline uint32_t cmj_permute(uint32_t i, uint32_t mask, uint32_t p) {
  i ^= p;
  i *= 0xe170893du;
  i ^= (i & mask) >> 3;
  i ^= (i & mask) >> 1;
  i *= (p >> 16) | 1u;
  i ^= (i & mask) >> 2;
  i ^= (i & mask) >> 5;
  i *= 0x9e501cc3u;
  i ^= (i & mask) >> 1;
  i ^= (i & mask) >> 4;
  return (i + (p >> 8)) & mask;
}

// 32 random bits from (i, p): C. Wellons' "lowbias32" integer hash (2018, found by his hash
// prospector) of i ^ p; for the jitter within a fine stratum and for seeds derived from seeds.
inline uint32_t cmj_hash(uint32_t i, uint32_t p) {
  i ^= p;
  i ^= i >> 16;
  i *= 0x7feb352du;
  i ^= i >> 15;
  i *= 0x846ca68bu;
  i ^= i >> 16;
  return i;
}

// The constant a seed is hashed with to derive the 1D value's second seed (cmj_z).
inline constexpr uint32_t kCmjRowSeed = 0x68bc21ebu;

// Fixed point of stratum t of 2^bits plus 32 - bits bits of jitter.
inline uint32_t cmj_fixed(uint32_t t, uint32_t jitter, uint32_t bits) { return (t << (32 - bits)) | (jitter >> bits); }

// Sample `index` of 2^bits: its cell of the m x n grid (m = 2^(bits / 2) columns), a random
// permutation of the sample indices by seed_index.
inline uint32_t cmj_cell(uint32_t index, uint32_t bits, uint32_t seed_index) {
  return cmj_permute(index, (1u << bits) - 1u, seed_index);
}
inline uint32_t cmj_column_bits(uint32_t bits) { return bits / 2; }

// The 2D point of cell c: x in column c mod m, at the fine offset the cell's row chooses (a
// permutation of the n rows' offsets by seed_x), y likewise; each jittered within its fine cell.
// A 1D value is the x of its dimension's point (as the Sobol sampler's): one per stratum of N.
inline uint32_t cmj_x(uint32_t cell, uint32_t bits, uint32_t seed_x) {
  const uint32_t a = cmj_column_bits(bits), c = bits - a;
  const uint32_t column = cell & ((1u << a) - 1u), row = cell >> a;
  const uint32_t offset = cmj_permute(row, (1u << c) - 1u, seed_x);
  return cmj_fixed((column << c) | offset, cmj_hash(cell, seed_x), bits);
}
inline uint32_t cmj_y(uint32_t cell, uint32_t bits, uint32_t seed_y) {
  const uint32_t a = cmj_column_bits(bits);
  const uint32_t column = cell & ((1u << a) - 1u), row = cell >> a;
  const uint32_t offset = cmj_permute(column, (1u << a) - 1u, seed_y);
  return cmj_fixed((row << a) | offset, cmj_hash(cell, seed_y), bits);
}

// The 1D value that goes with the 2D point of cell c (Sampler::get_1d_2d: a lobe choice with its
// direction, a light choice with its point, a moving camera's time with its film position),
// stratified with each of the point's coordinates as that point's x and y are with each other:
// the pair (column, row) picks the value's stratum of n by the Latin square
// f = (pi_m(column) << (c - a)) xor pi_n(row) (pi: random permutations; the n cells of a
// column then hold one value in each 1/n of [0, 1), the m cells of a row one in each 1/m), and
// within it the column picks the fine stratum (the m cells of one f lie in m different
// columns), so the N values are also one per stratum of N. Against the Sobol sampler's third
// dimension (docs/performance.md, levers, session 38) the points have 0.96 of the variance on
// plastics and 0.95-0.99 on the furnace, where the lobe choice matters, 0.50-0.80 on
// all_lights; a simpler split of the value by blocks of neighbouring cells lost to it on
// motion_blur (1.15 at 256 spp) and the furnace (1.05).
// cmj_z given its rows' seed, cmj_z_rows_seed(seed_z): the batch kernels take that once per
// pixel and dimension instead of once per sample.
inline uint32_t cmj_z_rows_seed(uint32_t seed_z) { return cmj_hash(seed_z, kCmjRowSeed); }
inline uint32_t cmj_z_with_rows(uint32_t cell, uint32_t bits, uint32_t seed_z, uint32_t seed_rows) {
  const uint32_t a = cmj_column_bits(bits), c = bits - a;
  const uint32_t column = cell & ((1u << a) - 1u), row = cell >> a;
  const uint32_t pi_column = cmj_permute(column, (1u << a) - 1u, seed_z);
  const uint32_t f = (pi_column << (c - a)) ^ cmj_permute(row, (1u << c) - 1u, seed_rows);
  // The fine stratum: the column's place in pi_m offset by a random number (a permutation of
  // the columns too).
  const uint32_t fine = (pi_column + (seed_rows >> 16)) & ((1u << a) - 1u);
  return cmj_fixed((f << a) | fine, cmj_hash(cell, seed_z), bits);
}
inline uint32_t cmj_z(uint32_t cell, uint32_t bits, uint32_t seed_z) {
  return cmj_z_with_rows(cell, bits, seed_z, cmj_z_rows_seed(seed_z));
}

// Whether a render of spp samples per pixel can take CMJ points: spp a power of two (a prefix of
// a larger pattern has more variance than the Sobol points; render.cpp) within cmj_bits_for's
// range. The one rule api/ (render.sampler) and the renderer both apply.
inline bool cmj_takes_count(uint32_t spp) { return std::has_single_bit(spp) && spp <= (1u << 24); }

// The CMJ size for a render of spp samples per pixel: bits of the smallest power of two >= spp,
// at least 1 (a shift by 32 is undefined); 0 (the Sobol sampler) above 2^24, where fixed point
// would leave a stratum no jitter in a float.
inline uint32_t cmj_bits_for(uint32_t spp) {
  uint32_t bits = 1;
  while (bits <= 24 && (1u << bits) < spp) ++bits;
  return bits <= 24 ? bits : 0u;
}

}  // namespace penumbra
