// The pre-routing guard: framing, encodings, body limit at limit and limit + 1, ranges, token.
#include "server/http/request_guard.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include "server/http/auth.h"

namespace penumbra::test {
namespace {

using namespace penumbra::server;

TEST(RequestGuard, FramingAndEncoding) {
  const BearerAuth none("");
  const GuardSettings s{100};
  httplib::Request req;
  req.method = "POST";
  req.path = "/v1/jobs";
  EXPECT_EQ(guard_request(req, s, none)->status, 411) << "POST without Content-Length";
  req.headers.emplace("Content-Length", "100");
  EXPECT_FALSE(guard_request(req, s, none)) << "exactly the limit passes";
  req.headers.find("Content-Length")->second = "101";
  EXPECT_EQ(guard_request(req, s, none)->status, 413);
  req.headers.find("Content-Length")->second = "10";
  req.headers.emplace("Content-Encoding", "gzip");
  EXPECT_EQ(guard_request(req, s, none)->status, 415);
  req.headers.find("Content-Encoding")->second = "identity";
  EXPECT_FALSE(guard_request(req, s, none));
  req.headers.emplace("Transfer-Encoding", "chunked");
  EXPECT_EQ(guard_request(req, s, none)->status, 411);

  httplib::Request get;
  get.method = "GET";
  get.path = "/v1/jobs/0123456789abcdef01234567/result";
  EXPECT_FALSE(guard_request(get, s, none));
  get.headers.emplace("Range", "bytes=0-10");
  EXPECT_FALSE(guard_request(get, s, none)) << "one range is fine";
  get.headers.find("Range")->second = "bytes=0-10,20-30";
  EXPECT_EQ(guard_request(get, s, none)->status, 416);
}

TEST(RequestGuard, TokenOnEveryRouteButHealthz) {
  const BearerAuth auth("tok");
  const GuardSettings s{100};
  httplib::Request req;
  req.method = "GET";
  for (const char* path : {"/healthz", "/readyz"}) {
    req.path = path;
    EXPECT_FALSE(guard_request(req, s, auth)) << path;
  }
  for (const char* path : {"/metrics", "/v1/jobs", "/v1/openapi.json", "/nowhere"}) {
    req.path = path;
    const auto p = guard_request(req, s, auth);
    ASSERT_TRUE(p) << path;
    EXPECT_EQ(p->status, 401);
  }
  req.headers.emplace("Authorization", "Bearer tok");
  EXPECT_FALSE(guard_request(req, s, auth));
}

}  // namespace
}  // namespace penumbra::test
