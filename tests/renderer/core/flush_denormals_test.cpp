// The render threads' float mode: denormal results flushed to zero and denormal inputs read as
// zero inside the scope, the IEEE default again after it.
#include "renderer/core/flush_denormals.h"

#include <gtest/gtest.h>

#include <limits>

namespace penumbra::test {
namespace {

// (volatile: computed at run time, in the thread's current mode, not folded by the compiler.)
float product(float a, float b) {
  volatile float x = a, y = b;
  return x * y;
}

TEST(FlushDenormals, InsideTheScopeOnlyAndRestoredAfter) {
  const float tiny = std::numeric_limits<float>::min();  // the smallest normal float
  const float denormal = product(tiny, 0.5f);
#if defined(__x86_64__) || defined(_M_X64)
  EXPECT_GT(denormal, 0.f);  // IEEE default: gradual underflow
  {
    const FlushDenormals scope;
    EXPECT_EQ(product(tiny, 0.5f), 0.f);     // a denormal result is flushed
    EXPECT_EQ(product(denormal, 4.f), 0.f);  // a denormal input reads as zero
    EXPECT_EQ(product(tiny, 2.f), 2.f * tiny);
  }
  EXPECT_EQ(product(tiny, 0.5f), denormal);
  EXPECT_EQ(product(denormal, 4.f), 2.f * tiny);
#else
  GTEST_SKIP() << "no such mode on this target";
#endif
}

}  // namespace
}  // namespace penumbra::test
