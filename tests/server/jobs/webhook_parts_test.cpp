// The pieces of webhook delivery: URL checks and the allow list, the signature (RFC 4231 test
// vectors), the backoff schedule; and the job options a submission carries.
#include <gtest/gtest.h>

#include "server/jobs/job_options.h"
#include "server/jobs/webhook_sender.h"
#include "server/jobs/webhook_signature.h"
#include "server/jobs/webhook_url.h"

namespace penumbra::test {
namespace {

using namespace server;

TEST(WebhookUrl, SplitsHttpAndHttpsAndRefusesTheRest) {
  auto u = parse_webhook_url("HTTPS://Hooks.Example.com/a/b?x=1");
  ASSERT_TRUE(u.url) << u.error;
  EXPECT_TRUE(u.url->https);
  EXPECT_EQ(u.url->host, "hooks.example.com");
  EXPECT_EQ(u.url->port, 443);
  EXPECT_EQ(u.url->target, "/a/b?x=1");
  EXPECT_EQ(u.url->origin(), "https://hooks.example.com:443");
  u = parse_webhook_url("http://127.0.0.1:8081");
  ASSERT_TRUE(u.url);
  EXPECT_EQ(u.url->port, 8081);
  EXPECT_EQ(u.url->target, "/");
  u = parse_webhook_url("http://[::1]:9000/h");
  ASSERT_TRUE(u.url) << u.error;
  EXPECT_EQ(u.url->host, "::1");
  EXPECT_EQ(u.url->origin(), "http://[::1]:9000");
  for (const char* bad :
       {"ftp://x/", "file:///etc/passwd", "http://", "http://a b/", "http://u:p@host/",
        "http://host:0/", "http://host:65536/", "http://host:80x/", "http://host/#frag",
        "gopher://127.0.0.1:25/", "http://ho_st/", "//host/", "http://[::1/"})
    EXPECT_FALSE(parse_webhook_url(bad).url) << bad;
}

TEST(WebhookUrl, AllowListMatchesHostAndPortExactly) {
  std::string error;
  const auto allowed = parse_allowed_hosts("hooks.example.com, 127.0.0.1:9000,[::1]:8443", error);
  ASSERT_TRUE(allowed) << error;
  ASSERT_EQ(allowed->size(), 3u);
  const auto ok = [&](const char* url) { return host_allowed(*parse_webhook_url(url).url, *allowed); };
  EXPECT_TRUE(ok("https://hooks.example.com/x"));
  EXPECT_TRUE(ok("http://HOOKS.example.com/x")) << "port 80 is http's default";
  EXPECT_FALSE(ok("https://hooks.example.com:8443/x")) << "no port: only the default";
  EXPECT_FALSE(ok("https://evil.hooks.example.com/x"));
  EXPECT_FALSE(ok("https://hooks.example.com.evil/x"));
  EXPECT_TRUE(ok("http://127.0.0.1:9000/"));
  EXPECT_FALSE(ok("http://127.0.0.1:9001/"));
  EXPECT_FALSE(ok("http://127.0.0.1/"));
  EXPECT_FALSE(ok("http://localhost:9000/"));
  EXPECT_TRUE(ok("https://[::1]:8443/"));
  EXPECT_FALSE(parse_allowed_hosts("a:b", error));
  EXPECT_FALSE(parse_allowed_hosts("http://x", error));
  EXPECT_TRUE(parse_allowed_hosts("", error)->empty()) << "none: webhooks off";
}

TEST(WebhookSignature, Rfc4231TestVectors) {
  // RFC 4231 section 4.3 (test case 2) and 4.2 (test case 1).
  EXPECT_EQ(hmac_sha256_hex("Jefe", "what do ya want for nothing?"),
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
  EXPECT_EQ(hmac_sha256_hex(std::string(20, '\x0b'), "Hi There"),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
  EXPECT_EQ(webhook_signature("Jefe", "what do ya want for nothing?"),
            "sha256=5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
}

TEST(WebhookBackoff, DoublesFromOneSecondWithEqualJitterAndACap) {
  EXPECT_DOUBLE_EQ(webhook_backoff_seconds(1, 0.0), 0.5);
  EXPECT_DOUBLE_EQ(webhook_backoff_seconds(1, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(webhook_backoff_seconds(2, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(webhook_backoff_seconds(4, 1.0), 8.0);
  EXPECT_DOUBLE_EQ(webhook_backoff_seconds(30, 1.0), 300.0);
  EXPECT_DOUBLE_EQ(webhook_backoff_seconds(1000, 0.0), 150.0);
}

TEST(JobOptions, TakenOutOfTheBodyWithTheirPointers) {
  std::string error;
  const auto allowed = *parse_allowed_hosts("127.0.0.1:9000", error);
  // No members: the body as it is.
  const std::string plain = R"({"version": 1, "camera": {}})";
  SplitSubmission s = split_job_options(plain, allowed, 64);
  EXPECT_EQ(s.scene_text, plain);
  EXPECT_TRUE(s.errors.empty());
  s = split_job_options(
      R"({"version": 1, "priority": -7, "notify": {"url": "http://127.0.0.1:9000/h", "secret": "0123456789abcdef"}})",
      allowed, 64);
  EXPECT_TRUE(s.errors.empty());
  EXPECT_EQ(s.options.priority, -7);
  EXPECT_EQ(s.options.notify_url, "http://127.0.0.1:9000/h");
  EXPECT_EQ(s.options.notify_secret, "0123456789abcdef");
  EXPECT_EQ(s.scene_text, R"({"version":1})");
  // A name inside the scene ("priority" as a material name) is not an option.
  s = split_job_options(R"({"materials": {"priority": {}}})", allowed, 64);
  EXPECT_TRUE(s.errors.empty());
  EXPECT_EQ(s.scene_text, R"({"materials": {"priority": {}}})");
  // Duplicates would be lost in the rewrite: reported.
  s = split_job_options(R"({"priority": 1, "priority": 2})", allowed, 64);
  ASSERT_FALSE(s.errors.empty());
  EXPECT_EQ(s.errors[0].pointer, "/priority");
  s = split_job_options(R"({"priority": 18446744073709551615})", allowed, 64);
  ASSERT_EQ(s.errors.size(), 1u);
  EXPECT_EQ(s.errors[0].pointer, "/priority");
  s = split_job_options(R"({"notify": "http://127.0.0.1:9000/h"})", allowed, 64);
  ASSERT_EQ(s.errors.size(), 1u);
  EXPECT_EQ(s.errors[0].pointer, "/notify");
  s = split_job_options(R"({"notify": {"url": "http://127.0.0.1:9000/h"}})", {}, 64);
  ASSERT_EQ(s.errors.size(), 2u);
  EXPECT_EQ(s.errors[0].pointer, "/notify/url") << "webhooks off";
  EXPECT_EQ(s.errors[1].pointer, "/notify/secret");
}

}  // namespace
}  // namespace penumbra::test
