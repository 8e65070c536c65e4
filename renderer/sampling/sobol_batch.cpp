#include "renderer/sampling/sobol_batch.h"

#include "renderer/core/simd_clones.h"
#include "renderer/sampling/sobol_gfni.h"

namespace penumbra {

// The loop is integer arithmetic and an exact int-to-float conversion (no table lookups, so no
// gathers): every SIMD clone gives the same bits.
namespace {

PENUMBRA_SIMD_CLONES
void scrambled_sobol_kernel(size_t n, const uint32_t* __restrict index,
                            const uint32_t* __restrict seed_index, const uint32_t* __restrict seed_x,
                            const uint32_t* __restrict seed_y, float* __restrict x,
                            float* __restrict y) {
  for (size_t i = 0; i < n; ++i) {
    const uint32_t shuffled = shuffled_sample_index(index[i], seed_index[i]);
    x[i] = scrambled_sobol_x(shuffled, seed_x[i]);
    y[i] = scrambled_sobol_y(shuffled, seed_y[i]);
  }
}

PENUMBRA_SIMD_CLONES
void scrambled_sobol_z_kernel(size_t n, const uint32_t* __restrict index,
                              const uint32_t* __restrict seed_index,
                              const uint32_t* __restrict seed_z, float* __restrict z) {
  for (size_t i = 0; i < n; ++i)
    z[i] = scrambled_sobol_z(shuffled_sample_index(index[i], seed_index[i]), seed_z[i]);
}

PENUMBRA_SIMD_CLONES
void cmj_cells_x_kernel(size_t n, uint32_t bits, const uint32_t* __restrict index,
                        const uint32_t* __restrict seed_index, const uint32_t* __restrict seed_x,
                        uint32_t* __restrict cell, float* __restrict x) {
  for (size_t i = 0; i < n; ++i) {
    const uint32_t c = cmj_cell(index[i], bits, seed_index[i]);
    cell[i] = c;
    x[i] = fixed_to_unit_float(cmj_x(c, bits, seed_x[i]));
  }
}

PENUMBRA_SIMD_CLONES
void cmj_y_kernel(size_t n, uint32_t bits, const uint32_t* __restrict cell, const uint32_t* __restrict seed_y,
                  float* __restrict y) {
  for (size_t i = 0; i < n; ++i) y[i] = fixed_to_unit_float(cmj_y(cell[i], bits, seed_y[i]));
}

PENUMBRA_SIMD_CLONES
void cmj_z_kernel(size_t n, uint32_t bits, const uint32_t* __restrict cell, const uint32_t* __restrict seed_z,
                  const uint32_t* __restrict seed_rows, float* __restrict z) {
  for (size_t i = 0; i < n; ++i)
    z[i] = fixed_to_unit_float(cmj_z_with_rows(cell[i], bits, seed_z[i], seed_rows[i]));
}

}  // namespace

void cmj_cells_x_batch(size_t n, uint32_t bits, const uint32_t* index, const uint32_t* seed_index,
                       const uint32_t* seed_x, uint32_t* cell, float* x) {
  cmj_cells_x_kernel(n, bits, index, seed_index, seed_x, cell, x);
}

void cmj_y_batch(size_t n, uint32_t bits, const uint32_t* cell, const uint32_t* seed_y, float* y) {
  cmj_y_kernel(n, bits, cell, seed_y, y);
}

void cmj_z_batch(size_t n, uint32_t bits, const uint32_t* cell, const uint32_t* seed_z,
                 const uint32_t* seed_rows, float* z) {
  cmj_z_kernel(n, bits, cell, seed_z, seed_rows, z);
}

void scrambled_sobol_z_batch_portable(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                      const uint32_t* seed_z, float* z) {
  scrambled_sobol_z_kernel(n, index, seed_index, seed_z, z);
}

void scrambled_sobol_batch_portable(size_t n, const uint32_t* index, const uint32_t* seed_index,
                                    const uint32_t* seed_x, const uint32_t* seed_y, float* x, float* y) {
  scrambled_sobol_kernel(n, index, seed_index, seed_x, seed_y, x, y);
}

void scrambled_sobol_z_batch(size_t n, const uint32_t* index, const uint32_t* seed_index,
                             const uint32_t* seed_z, float* z) {
  if (sobol_gfni_available()) return scrambled_sobol_z_batch_gfni(n, index, seed_index, seed_z, z);
  scrambled_sobol_z_batch_portable(n, index, seed_index, seed_z, z);
}

void scrambled_sobol_batch(size_t n, const uint32_t* index, const uint32_t* seed_index,
                           const uint32_t* seed_x, const uint32_t* seed_y, float* x, float* y) {
  if (sobol_gfni_available()) return scrambled_sobol_batch_gfni(n, index, seed_index, seed_x, seed_y, x, y);
  scrambled_sobol_batch_portable(n, index, seed_index, seed_x, seed_y, x, y);
}

}  // namespace penumbra
