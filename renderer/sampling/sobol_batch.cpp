#include "renderer/sampling/sobol_batch.h"

namespace penumbra {

// GCC compiles the loop once per target and picks one at load time (an ifunc): baseline x86-64
// (SSE2) for any CPU, x86-64-v3 (AVX2) and x86-64-v4 (AVX-512). Only integer operations and an
// exact int-to-float conversion (no table lookups, so no gathers), so every clone gives the same bits. Other compilers (the
// libFuzzer build uses clang) get the portable loop.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define PENUMBRA_SIMD_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define PENUMBRA_SIMD_CLONES
#endif

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

}  // namespace

void scrambled_sobol_batch(size_t n, const uint32_t* index, const uint32_t* seed_index,
                           const uint32_t* seed_x, const uint32_t* seed_y, float* x, float* y) {
  scrambled_sobol_kernel(n, index, seed_index, seed_x, seed_y, x, y);
}

}  // namespace penumbra
