#pragma once
// What the SIMD stages' loops over arrays are written with: a lane's condition as an integer
// mask, selects between values every lane computes, and a finiteness test in integer
// arithmetic. Loops in this form if-convert and vectorise (GCC 12); see render/surface_stage.h.
#include <cstdint>
#include <cstring>

namespace penumbra {

// A lane's condition as an integer mask (all bits or none), for the stages' loops over arrays:
// conditions combine with integer &, | and ~, and only selects read them, both sides computed,
// so the loops if-convert. (Combined as bools, GCC 12 turns some of them into selects between
// bools, which its vectoriser does not support.)
using Mask = int32_t;
[[gnu::always_inline]] inline Mask mask(bool b) { return b ? -1 : 0; }
template <class T>
[[gnu::always_inline]] inline T when(Mask m, T a, T b) {
  return m != 0 ? a : b;
}

namespace lane {

// Whether x is finite, as a mask made by integer arithmetic alone: |x|'s bits lie below
// infinity's. (As a comparison, GCC 12 folds several such masks into bools and selects between
// them, which its vectoriser does not support.)
[[gnu::always_inline]] inline Mask finite(float x) {
  int32_t b;
  std::memcpy(&b, &x, sizeof b);
  return ((b & 0x7fffffff) - 0x7f800000) >> 31;
}

}  // namespace lane
}  // namespace penumbra
