#pragma once
// Helpers of the tests that compare a SIMD kernel with its scalar original to the bit.
#include <cstdint>
#include <cstring>

namespace penumbra::test {

inline uint32_t float_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// Marsaglia's xorshift32: a fixed, portable stream of test inputs.
struct XorShift32 {
  uint32_t state;
  uint32_t next() {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return state;
  }
  float uniform() { return float(next() >> 8) * 0x1p-24f; }
};

}  // namespace penumbra::test
