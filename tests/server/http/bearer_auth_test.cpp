// The bearer token check: constant-time comparison, the Authorization header's forms.
#include <gtest/gtest.h>

#include "server/http/auth.h"

namespace penumbra::test {
namespace {

using namespace penumbra::server;

TEST(Auth, ConstantTimeEqual) {
  EXPECT_TRUE(constant_time_equal("abc", "abc"));
  EXPECT_FALSE(constant_time_equal("abc", "abd"));
  EXPECT_FALSE(constant_time_equal("abc", "abcd"));
  EXPECT_FALSE(constant_time_equal("", "a"));
  EXPECT_TRUE(constant_time_equal("", ""));
}

TEST(Auth, BearerHeader) {
  const BearerAuth auth("tok");
  EXPECT_TRUE(auth.allows("Bearer tok"));
  EXPECT_TRUE(auth.allows("bearer tok"));
  EXPECT_FALSE(auth.allows("Bearer tok2"));
  EXPECT_FALSE(auth.allows("Basic dG9rOg=="));
  EXPECT_FALSE(auth.allows(""));
  EXPECT_FALSE(auth.allows("Bearer "));
  EXPECT_TRUE(BearerAuth("").allows(""));
}

}  // namespace
}  // namespace penumbra::test
