// Head lines checked before the library parses them: RFC 9110 field values and names, a long
// Range.
#include "server/http/header_line_check.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using server::check_head_line;

int status(std::string_view line, std::size_t index = 1) {
  const auto p = check_head_line(line, index, server::ConnectionLimits{});
  return p ? p->status : 0;
}

TEST(HeaderLineCheck, FieldValues) {
  using namespace std::string_view_literals;
  EXPECT_EQ(status("Authorization: Bearer abc"), 0);
  EXPECT_EQ(status("X: a\tb \x80\xff"), 0);
  EXPECT_EQ(status("Authorization: Bearer abc\0junk"sv), 400);
  EXPECT_EQ(status("X: a\x1f"), 400);
  EXPECT_EQ(status("X: a\x7f"), 400);
  EXPECT_EQ(status("X: a\rb"), 400);
}

TEST(HeaderLineCheck, FieldNames) {
  EXPECT_EQ(status("no colon"), 400);
  EXPECT_EQ(status(": empty name"), 400);
  EXPECT_EQ(status("Bad Name: x"), 400);
  EXPECT_EQ(status("X-Ok_1.2~: x"), 0);
}

TEST(HeaderLineCheck, RequestLine) {
  EXPECT_EQ(status("GET / HTTP/1.1", 0), 0);
  EXPECT_EQ(status(std::string_view("GET /\0 HTTP/1.1", 15), 0), 400);
}

TEST(HeaderLineCheck, RangeLengthAtTheBoundary) {
  const std::string at = "bytes=" + std::string(121, '1') + "-";  // 128 bytes
  ASSERT_EQ(at.size(), 128u);
  EXPECT_EQ(status("Range: " + at), 0);
  EXPECT_EQ(status("Range: " + at + "1"), 416);
}

}  // namespace
}  // namespace penumbra::test
