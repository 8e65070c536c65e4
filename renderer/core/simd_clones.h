#pragma once
// PENUMBRA_SIMD_CLONES before a function over arrays: GCC compiles it once per target, baseline
// x86-64 (SSE2, any CPU), x86-64-v3 (AVX2) and x86-64-v4 (AVX-512), and the loader picks the
// best the CPU has (an ifunc), so loops vectorise as wide as the machine allows while the binary
// still runs on any x86-64. Other compilers (the libFuzzer build uses clang) and targets get the
// portable function. Clones must give the same bits: integer arithmetic, or float arithmetic
// compiled without FMA contraction (see renderer/CMakeLists.txt).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define PENUMBRA_SIMD_CLONES \
  __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define PENUMBRA_SIMD_CLONES
#endif
