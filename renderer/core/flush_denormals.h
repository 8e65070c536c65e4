#pragma once
// Denormal floats flushed to zero (FTZ) and read as zero (DAZ) in a scope: the render threads'
// mode while they trace and shade, as Embree's documentation advises for its callers.
//
// Why: an SSE/AVX multiply or add whose input or result is denormal takes a microcode assist
// of about a hundred cycles on Intel cores. The renderer computes no denormal worth keeping (a
// radiance, throughput or pdf below 1.2e-38 is zero to any image), but its SIMD kernels can meet
// denormals they never computed: GCC's AVX-512 clones turn a load under a condition into a
// merge-masked load, whose unloaded lanes keep what the register held before, and arithmetic on
// those lanes costs an assist when that leftover is denormal. Which leftovers are denormal
// depends on the code the build happened to run before: a light tree kernel with such a load was
// 1.22x slower on many_lights in one build and not in another, and 0.82 of that time with this
// mode on (docs/performance.md, levers, session 44). The mode takes the lottery away.
//
// Restored on leaving the scope, so code the thread runs afterwards (TBB's other work, the
// caller's) keeps the IEEE default. Other targets: no change.
#if defined(__x86_64__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

namespace penumbra {

class FlushDenormals {
 public:
#if defined(__x86_64__) || defined(_M_X64)
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero); }
  ~FlushDenormals() { _mm_setcsr(saved_); }
#else
  FlushDenormals() = default;
#endif
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
#if defined(__x86_64__) || defined(_M_X64)
  static constexpr unsigned kFlushToZero = 0x8000u, kDenormalsAreZero = 0x0040u;  // MXCSR bits
  unsigned saved_;
#endif
};

}  // namespace penumbra
