// Idempotency-Key: the same key and body give the same job; the same key with another body is
// 422 (as draft-ietf-httpapi-idempotency-key-header specifies).
#include <gtest/gtest.h>

#include "server_process.h"

namespace penumbra::test {
namespace {

TEST(Idempotency, SameKeySameBodyIsTheSameJob) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string body = tiny_scene(8, 8, 1).dump();
  auto first = post_json(*c, "/v1/jobs", body, {{"Idempotency-Key", "order-42"}});
  ASSERT_EQ(first->status, 202);
  EXPECT_FALSE(first->has_header("Idempotent-Replayed"));
  auto second = post_json(*c, "/v1/jobs", body, {{"Idempotency-Key", "order-42"}});
  ASSERT_EQ(second->status, 202);
  EXPECT_EQ(second->get_header_value("Idempotent-Replayed"), "true");
  EXPECT_EQ(Json::parse(first->body)["id"], Json::parse(second->body)["id"]);
  EXPECT_EQ(first->get_header_value("Location"), second->get_header_value("Location"));
  // The quoted structured-field form names the same key.
  auto quoted = post_json(*c, "/v1/jobs", body, {{"Idempotency-Key", "\"order-42\""}});
  EXPECT_EQ(Json::parse(quoted->body)["id"], Json::parse(first->body)["id"]);
  EXPECT_EQ(Json::parse(c->Get("/v1/jobs")->body)["jobs"].size(), 1u);
  // Without a key, the same body is a new job.
  EXPECT_NE(Json::parse(post_json(*c, "/v1/jobs", body)->body)["id"], Json::parse(first->body)["id"]);
}

TEST(Idempotency, SameKeyOtherBodyIs422) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  auto first = post_json(*c, "/v1/jobs", tiny_scene(8, 8, 1).dump(), {{"Idempotency-Key", "k1"}});
  ASSERT_EQ(first->status, 202);
  auto other = post_json(*c, "/v1/jobs", tiny_scene(8, 8, 2).dump(), {{"Idempotency-Key", "k1"}});
  ASSERT_EQ(other->status, 422);
  const Json p = Json::parse(other->body);
  EXPECT_EQ(p["type"], "urn:penumbra:problem:idempotency-key-reused");
  EXPECT_EQ(p["job"], first->get_header_value("Location"));
}

TEST(Idempotency, KeySurvivesRestartAndIsFreedByDelete) {
  TempDir dir;
  const std::string body = tiny_scene(8, 8, 1).dump();
  std::string id;
  {
    ServerProcess server(dir.path());
    auto c = server.client();
    id = Json::parse(post_json(*c, "/v1/jobs", body, {{"Idempotency-Key", "k"}})->body)["id"];
    wait_for_state(*c, id, {"succeeded"});
  }
  ServerProcess server(dir.path());
  auto c = server.client();
  EXPECT_EQ(Json::parse(post_json(*c, "/v1/jobs", body, {{"Idempotency-Key", "k"}})->body)["id"], id);
  EXPECT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status, 204);
  const Json fresh = Json::parse(post_json(*c, "/v1/jobs", body, {{"Idempotency-Key", "k"}})->body);
  EXPECT_NE(fresh["id"], id);
}

}  // namespace
}  // namespace penumbra::test
