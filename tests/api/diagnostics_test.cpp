// Pointer escaping, typo suggestions and quoting of user strings.
#include "api/diagnostics.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using namespace api;

TEST(Diagnostics, PointerTokensFollowRfc6901) {
  EXPECT_EQ(escape_pointer_token("plain"), "plain");
  EXPECT_EQ(escape_pointer_token("a/b"), "a~1b");
  EXPECT_EQ(escape_pointer_token("~1"), "~01");
  EXPECT_EQ(child_pointer("/materials", "x/y"), "/materials/x~1y");
  EXPECT_EQ(child_pointer("/objects", std::size_t(3)), "/objects/3");
  EXPECT_EQ(child_pointer("", ""), "/");
}

TEST(Diagnostics, ClosestMatch) {
  const std::vector<std::string> keys = {"roughness", "color", "ior", "absorption"};
  EXPECT_EQ(closest_match("roughnes", keys), "roughness");
  EXPECT_EQ(closest_match("colour", keys), "color");
  EXPECT_EQ(closest_match("io", keys), "ior");
  EXPECT_EQ(closest_match("banana", keys), "");
  EXPECT_EQ(closest_match("x", {"g"}), "");
  EXPECT_EQ(closest_match(std::string(1000, 'a'), keys), "");
}

TEST(Diagnostics, QuotedUserStringsStayShortAndValidUtf8) {
  EXPECT_EQ(quote_user_string("gold"), "'gold'");
  EXPECT_EQ(quote_user_string("a\nb"), "'a?b'");
  std::string long_text(63, 'a');
  long_text += "\xc3\xa9\xc3\xa9";  // "é" straddles the 64-byte cut
  const std::string quoted = quote_user_string(long_text);
  EXPECT_EQ(quoted, "'" + std::string(63, 'a') + "...'");
}

TEST(Diagnostics, CapKeepsTheCount) {
  Diagnostics diag;
  for (int i = 0; i < 150; ++i) diag.warning("/w", "w");
  diag.error("/e", "e");
  EXPECT_EQ(diag.error_count(), 1u);
  const auto warnings = diag.take_warnings();
  ASSERT_EQ(warnings.size(), 101u);
  EXPECT_EQ(warnings.back().message, "50 more warnings not shown");
  EXPECT_EQ(diag.take_errors().size(), 1u);
}

}  // namespace
}  // namespace penumbra::test
