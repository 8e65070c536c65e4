// The bounded multipart/form-data parser of the one-shot job form (server/http/multipart.h).
#include "server/http/multipart.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace penumbra::test {
namespace {

using server::MultipartLimits;
using server::parse_multipart;

std::string part(const std::string& disposition, const std::string& data,
                 const std::string& extra = "") {
  return "--B\r\nContent-Disposition: " + disposition + "\r\n" + extra + "\r\n" + data + "\r\n";
}

TEST(Multipart, BoundaryFromContentType) {
  EXPECT_EQ(server::multipart_boundary("multipart/form-data; boundary=abc"), "abc");
  EXPECT_EQ(server::multipart_boundary("Multipart/Form-Data; charset=x; boundary=\"a b\""), "a b");
  EXPECT_FALSE(server::multipart_boundary("multipart/form-data"));
  EXPECT_FALSE(server::multipart_boundary("multipart/mixed; boundary=abc"));
  EXPECT_FALSE(server::multipart_boundary("multipart/form-data; boundary=" + std::string(71, 'x')));
  EXPECT_TRUE(server::multipart_boundary("multipart/form-data; boundary=" + std::string(70, 'x')));
}

TEST(Multipart, PartsAreViewsIntoTheBody) {
  const std::string body = "preamble\r\n" +
                           part("form-data; name=\"scene\"; filename=\"s.json\"", "{}",
                                "Content-Type: application/json\r\n") +
                           part("form-data; name=\"meshes/a.ply\"", "ply\r\nbinary\r\n--Bx") +
                           "--B--\r\nepilogue";
  const auto r = parse_multipart(body, "B", {});
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_EQ(r.parts.size(), 2u);
  EXPECT_EQ(r.parts[0].name, "scene");
  EXPECT_EQ(r.parts[0].filename, "s.json");
  EXPECT_EQ(r.parts[0].content_type, "application/json");
  EXPECT_EQ(r.parts[0].data, "{}");
  EXPECT_EQ(r.parts[1].name, "meshes/a.ply");
  EXPECT_EQ(r.parts[1].data, "ply\r\nbinary\r\n--Bx");
  EXPECT_GE(r.parts[1].data.data(), body.data());
  EXPECT_LE(r.parts[1].data.data() + r.parts[1].data.size(), body.data() + body.size());
}

TEST(Multipart, QuotedNamesUnescape) {
  const auto r = parse_multipart(part(R"(form-data; name="a\"b")", "x") + "--B--", "B", {});
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.parts[0].name, "a\"b");
}

TEST(Multipart, PartCountAtTheBoundary) {
  MultipartLimits l;
  l.max_parts = 2;
  const std::string two = part("form-data; name=a", "1") + part("form-data; name=b", "2");
  EXPECT_TRUE(parse_multipart(two + "--B--", "B", l).error.empty());
  EXPECT_FALSE(parse_multipart(two + part("form-data; name=c", "3") + "--B--", "B", l).error.empty());
}

TEST(Multipart, PartHeadLimits) {
  MultipartLimits l;
  l.max_part_headers = 2;
  l.max_part_head_bytes = 100;
  EXPECT_TRUE(parse_multipart(part("form-data; name=a", "1", "X: y\r\n") + "--B--", "B", l).error.empty());
  EXPECT_FALSE(parse_multipart(part("form-data; name=a", "1", "X: y\r\nZ: w\r\n") + "--B--", "B", l)
                   .error.empty());
  EXPECT_FALSE(parse_multipart(part("form-data; name=a", "1", "X: " + std::string(100, 'y') + "\r\n") +
                                   "--B--",
                               "B", l)
                   .error.empty());
}

TEST(Multipart, MalformedBodiesAreErrors) {
  for (const std::string& body : std::vector<std::string>{std::string("nothing"), part("form-data", "x") + "--B--",
        part("attachment; name=a", "x") + "--B--", part("form-data; name=\"a", "x") + "--B--",
        std::string("--B\r\nContent-Disposition: form-data; name=a\r\n\r\nunterminated"),
        std::string("--B\r\n\r\nno disposition\r\n--B--"), std::string("--Bjunk"),
        part("form-data; name=a; name=b", "x") + "--B--"})
    EXPECT_FALSE(parse_multipart(body, "B", {}).error.empty()) << body;
}

}  // namespace
}  // namespace penumbra::test
