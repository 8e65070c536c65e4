// Bearer token on and off; the refusal to listen beyond loopback without a token.
#include <gtest/gtest.h>

#include "server_process.h"

namespace penumbra::test {
namespace {

TEST(Auth, OffByDefaultOnLoopback) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  EXPECT_EQ(c->Get("/v1/jobs")->status, 200);
  EXPECT_EQ(c->Get("/metrics")->status, 200);
}

TEST(Auth, TokenRequiredOnEveryRouteButHealthz) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--token", "correct-horse"});
  auto anonymous = server.client();
  auto wrong = server.client("battery-staple");
  auto right = server.client("correct-horse");
  // Probes (a kubelet, a load balancer) carry no token: /healthz and /readyz need none.
  EXPECT_EQ(anonymous->Get("/healthz")->status, 200);
  EXPECT_EQ(anonymous->Get("/readyz")->status, 200);
  for (const char* path : {"/metrics", "/v1/jobs", "/v1/openapi.json",
                           "/v1/jobs/0123456789abcdef01234567"}) {
    auto res = anonymous->Get(path);
    EXPECT_EQ(res->status, 401) << path;
    EXPECT_EQ(res->get_header_value("WWW-Authenticate"), "Bearer realm=\"penumbra\"");
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json");
    EXPECT_EQ(wrong->Get(path)->status, 401) << path;
  }
  EXPECT_EQ(anonymous->Post("/v1/jobs", tiny_scene().dump(), "application/json")->status, 401);
  EXPECT_EQ(right->Get("/readyz")->status, 200);
  const std::string id = submit(*right, tiny_scene(8, 8, 1));
  wait_for_state(*right, id, {"succeeded"});
  EXPECT_EQ(right->Get(("/v1/jobs/" + id + "/result").c_str())->status, 200);
  EXPECT_EQ(anonymous->Get(("/v1/jobs/" + id + "/result").c_str())->status, 401);
  EXPECT_EQ(anonymous->Delete(("/v1/jobs/" + id).c_str())->status, 401);
}

TEST(Auth, TokenFromTheEnvironment) {
  TempDir dir;
  ServerProcess server(dir.path(), {}, {"PENUMBRA_TOKEN=from-env"});
  EXPECT_EQ(server.client()->Get("/v1/jobs")->status, 401);
  EXPECT_EQ(server.client("from-env")->Get("/v1/jobs")->status, 200);
}

TEST(Auth, RefusesNonLoopbackWithoutTokenUnlessInsecure) {
  TempDir dir;
  const RunResult refused = run_serve_to_exit({"--host", "0.0.0.0", "--port", "0", "--data-dir", dir.path()});
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("without a token"), std::string::npos) << refused.output;
  const RunResult refused_env = run_serve_to_exit({"--port", "0", "--data-dir", dir.path()},
                                                  {"PENUMBRA_HOST=0.0.0.0"});
  EXPECT_EQ(refused_env.exit_code, 2);
  // With a token, or with --insecure, it starts (and answers on loopback too).
  ServerProcess with_token(dir.path() + "/a", {"--host", "0.0.0.0", "--token", "t"});
  EXPECT_EQ(with_token.client()->Get("/healthz")->status, 200);
  ServerProcess insecure(dir.path() + "/b", {"--host", "0.0.0.0", "--insecure"});
  EXPECT_EQ(insecure.client()->Get("/v1/jobs")->status, 200);
}

}  // namespace
}  // namespace penumbra::test
