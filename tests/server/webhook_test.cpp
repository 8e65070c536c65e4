// Webhooks through the real binary and a receiver on loopback: signature, retries with the same
// delivery id, delivery status in the job and in /metrics, hosts not allowed (422), a pending
// delivery surviving kill -9, and the secret never shown.
#include <gtest/gtest.h>

#include "notify_support.h"
#include "server/jobs/webhook_signature.h"

namespace penumbra::test {
namespace {

using namespace std::chrono_literals;

const std::string kSecret = "s3cr3t-for-the-loopback-receiver";

Json with_notify(Json scene, const std::string& url, const std::string& secret = kSecret) {
  scene["notify"] = {{"url", url}, {"secret", secret}};
  return scene;
}

std::vector<std::string> allow(const WebhookReceiver& r) {
  return {"--webhook-allow-hosts", "127.0.0.1:" + std::to_string(r.port())};
}

TEST(Webhook, SignedRetriedTwiceThenDeliveredWithOneDeliveryId) {
  TempDir dir;
  WebhookReceiver receiver(/*failures=*/2);
  ServerProcess server(dir.path(), allow(receiver));
  auto c = server.client();
  auto res = post_json(*c, "/v1/jobs", with_notify(tiny_scene(), receiver.url()).dump());
  ASSERT_EQ(res->status, 202) << res->body;
  EXPECT_EQ(res->body.find(kSecret), std::string::npos) << "the secret is never shown";
  const std::string id = Json::parse(res->body)["id"];
  const Json accepted = Json::parse(res->body);
  EXPECT_EQ(accepted["notify"]["url"], receiver.url());
  EXPECT_EQ(accepted["notify"]["delivery"], "waiting");

  const auto hits = receiver.wait_for(3, 20s);
  ASSERT_EQ(hits.size(), 3u);
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const auto& h = hits[i];
    EXPECT_EQ(h.signature, server::webhook_signature(kSecret, h.body)) << "HMAC-SHA256 of the body";
    EXPECT_EQ(h.delivery, id + "-succeeded") << "the same idempotency id on every attempt";
    EXPECT_EQ(h.event, "job.succeeded");
    EXPECT_EQ(h.attempt, std::to_string(i + 1));
    EXPECT_EQ(h.content_type, "application/json");
    EXPECT_EQ(h.body, hits[0].body) << "the same body on every attempt";
    EXPECT_EQ(h.body.find(kSecret), std::string::npos);
  }
  const Json body = Json::parse(hits[0].body);
  EXPECT_EQ(body["id"], id);
  EXPECT_EQ(body["state"], "succeeded");
  EXPECT_EQ(body["notify"], Json({{"url", receiver.url()}}));

  // The status is recorded once the third attempt's answer came.
  Json job;
  for (int i = 0; i < 100; ++i) {
    job = get_job(*c, id);
    if (job["notify"]["delivery"] == "delivered") break;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(job["notify"]["delivery"], "delivered") << job.dump();
  EXPECT_EQ(job["notify"]["attempts"], 3);
  EXPECT_EQ(job["notify"]["last_status"], 200);
  EXPECT_TRUE(job["notify"]["delivered_at"].is_string());
  EXPECT_TRUE(job["notify"]["last_error"].is_null());
  EXPECT_EQ(metric_line(*c, "penumbra_webhook_attempts_total{result=\"failed_attempt\"}"),
            "penumbra_webhook_attempts_total{result=\"failed_attempt\"} 2");
  EXPECT_EQ(metric_line(*c, "penumbra_webhook_attempts_total{result=\"delivered\"}"),
            "penumbra_webhook_attempts_total{result=\"delivered\"} 1");
  std::this_thread::sleep_for(1500ms);
  EXPECT_EQ(receiver.hits().size(), 3u) << "nothing after the 2xx";
  EXPECT_EQ(c->Get(("/v1/jobs/" + id).c_str())->body.find(kSecret), std::string::npos);
}

TEST(Webhook, HostsNotAllowedAndWebhooksOffAre422OnNotifyUrl) {
  TempDir dir;
  WebhookReceiver receiver(0);
  {
    ServerProcess off(dir.path() + "/off");
    auto c = off.client();
    auto res = post_json(*c, "/v1/jobs", with_notify(tiny_scene(), receiver.url()).dump());
    ASSERT_EQ(res->status, 422);
    EXPECT_EQ(Json::parse(res->body)["errors"][0]["pointer"], "/notify/url") << res->body;
  }
  ServerProcess server(dir.path() + "/on", allow(receiver));
  auto c = server.client();
  const std::string other_port = "http://127.0.0.1:" + std::to_string(receiver.port() + 1) + "/hook";
  for (const std::string& url :
       {std::string("http://10.0.0.1/hook"), other_port, std::string("http://localhost:") +
                                                            std::to_string(receiver.port()) + "/",
        std::string("ftp://127.0.0.1/hook"), std::string("file:///etc/passwd"),
        "http://user:pw@127.0.0.1:" + std::to_string(receiver.port()) + "/hook"}) {
    auto res = post_json(*c, "/v1/jobs", with_notify(tiny_scene(), url).dump());
    ASSERT_EQ(res->status, 422) << url;
    const Json p = Json::parse(res->body);
    EXPECT_EQ(p["errors"][0]["pointer"], "/notify/url") << url << " " << res->body;
    EXPECT_EQ(res->body.find(kSecret), std::string::npos);
  }
  // A short secret, a missing one, unknown members.
  auto res = post_json(*c, "/v1/jobs", with_notify(tiny_scene(), receiver.url(), "short").dump());
  ASSERT_EQ(res->status, 422);
  EXPECT_EQ(Json::parse(res->body)["errors"][0]["pointer"], "/notify/secret");
  EXPECT_EQ(res->body.find("short\""), std::string::npos) << "not even a bad secret is echoed";
  Json scene = tiny_scene();
  scene["notify"] = {{"url", receiver.url()}, {"secret", kSecret}, {"events", "all"}};
  res = post_json(*c, "/v1/jobs", scene.dump());
  ASSERT_EQ(res->status, 422);
  EXPECT_EQ(Json::parse(res->body)["errors"][0]["pointer"], "/notify/events");
  EXPECT_TRUE(receiver.hits().empty());
}

TEST(Webhook, APendingDeliverySurvivesKill9AndIsDeliveredAfterTheRestart) {
  TempDir dir;
  WebhookReceiver receiver(/*failures=*/1000);
  std::string id;
  {
    ServerProcess server(dir.path(), allow(receiver));
    auto c = server.client();
    id = submit(*c, with_notify(tiny_scene(), receiver.url()));
    ASSERT_GE(receiver.wait_for(1, 20s).size(), 1u);
    // Wait until the failed attempt is recorded (the retry is planned), then kill.
    Json job;
    for (int i = 0; i < 200; ++i) {
      job = get_job(*c, id);
      if (job["notify"]["attempts"] >= 1) break;
      std::this_thread::sleep_for(20ms);
    }
    EXPECT_EQ(job["notify"]["delivery"], "retrying") << job.dump();
    EXPECT_EQ(job["notify"]["last_status"], 503);
    EXPECT_EQ(job["notify"]["last_error"], "HTTP 503");
    EXPECT_TRUE(job["notify"]["next_attempt_at"].is_string());
    std::this_thread::sleep_for(100ms);  // the store writer commits the status (no wait for it)
    server.signal(SIGKILL);
    server.wait_exit(10s);
  }
  const std::size_t before = receiver.hits().size();
  receiver.set_failures(0);
  ServerProcess again(dir.path(), allow(receiver));
  const auto hits = receiver.wait_for(before + 1, 20s);
  ASSERT_EQ(hits.size(), before + 1);
  EXPECT_EQ(hits.back().delivery, id + "-succeeded");
  EXPECT_EQ(hits.back().body, hits.front().body) << "the same body after the restart";
  EXPECT_EQ(hits.back().signature, server::webhook_signature(kSecret, hits.back().body));
  auto c = again.client();
  Json job;
  for (int i = 0; i < 100; ++i) {
    job = get_job(*c, id);
    if (job["notify"]["delivery"] == "delivered") break;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(job["notify"]["delivery"], "delivered");
  EXPECT_EQ(job["notify"]["attempts"], int(before) + 1);
}

TEST(Webhook, GivenUpAfterTheRetryTimeIsVisible) {
  TempDir dir;
  WebhookReceiver receiver(/*failures=*/1000);
  ServerProcess server(dir.path(), {"--webhook-allow-hosts",
                                    "127.0.0.1:" + std::to_string(receiver.port()),
                                    "--webhook-retry-for", "2s"});
  auto c = server.client();
  const std::string id = submit(*c, with_notify(tiny_scene(), receiver.url()));
  Json job;
  for (int i = 0; i < 500; ++i) {
    job = get_job(*c, id);
    if (job["notify"]["delivery"] == "failed") break;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(job["notify"]["delivery"], "failed") << job.dump();
  EXPECT_GE(job["notify"]["attempts"], 2);
  EXPECT_EQ(job["notify"]["last_error"], "HTTP 503");
  EXPECT_EQ(metric_line(*c, "penumbra_webhook_attempts_total{result=\"gave_up\"}"),
            "penumbra_webhook_attempts_total{result=\"gave_up\"} 1");
}

// https:// goes through cpp-httplib's OpenSSL client: against a receiver that speaks plain HTTP
// the TLS handshake fails, and the job says so (the https path is wired; a certificate check
// against the system's CAs needs a real host, not available to the tests).
TEST(Webhook, HttpsUrlsUseTlsAndAFailedHandshakeIsReported) {
  TempDir dir;
  WebhookReceiver receiver(0);
  ServerProcess server(dir.path(), {"--webhook-allow-hosts",
                                    "127.0.0.1:" + std::to_string(receiver.port()),
                                    "--webhook-retry-for", "0s"});
  auto c = server.client();
  const std::string url = "https://127.0.0.1:" + std::to_string(receiver.port()) + "/hook";
  const std::string id = submit(*c, with_notify(tiny_scene(), url));
  Json job;
  for (int i = 0; i < 500; ++i) {
    job = get_job(*c, id);
    if (job["notify"]["delivery"] == "failed") break;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(job["notify"]["delivery"], "failed") << job.dump();
  EXPECT_EQ(job["notify"]["attempts"], 1);
  EXPECT_EQ(job["notify"]["last_error"], "TLS handshake failed");
  EXPECT_TRUE(receiver.hits().empty()) << "nothing reached the handler in clear text";
}

}  // namespace
}  // namespace penumbra::test
