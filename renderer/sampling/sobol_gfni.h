#pragma once
// The batch sampler's kernels (sobol_batch.h) for CPUs with AVX-512 and GFNI (Ice Lake and Zen 4
// on), chosen at run time. Most of a scrambled Sobol value's operations are GF(2)-linear maps of
// its 32 bits -- bit reversals around each Laine-Karras permutation, Sobol's generator matrices --
// which portable code builds from shifts and masks (a reversal: 15 operations; the third
// dimension's matrix: 160, a masked XOR per column). GFNI's affine instruction applies an 8 x 8
// bit matrix to every byte at once, so a reversal is one affine step and one byte shuffle, and a
// 32 x 32 matrix one affine step per non-zero 8 x 8 block. The values are the portable kernels'
// to the bit (integer operations and the same exact conversion).
#include <cstddef>
#include <cstdint>

namespace penumbra {

// Whether this CPU (and its operating system) runs the kernels below.
bool sobol_gfni_available();

// As scrambled_sobol_batch and scrambled_sobol_z_batch; only where sobol_gfni_available().
void scrambled_sobol_batch_gfni(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                const uint32_t* seed_x, const uint32_t* seed_y, float* x, float* y);
void scrambled_sobol_z_batch_gfni(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                  const uint32_t* seed_z, float* z);

}  // namespace penumbra
