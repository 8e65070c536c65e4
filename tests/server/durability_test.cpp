// Restart durability: finished results survive, queued jobs still run, a render killed with
// SIGKILL runs again, nothing answered 202 is lost; finished jobs expire after --retention.
#include <gtest/gtest.h>

#include <csignal>

#include "server_process.h"

namespace penumbra::test {
namespace {

TEST(Durability, KillDashNineDuringARenderLosesNothing) {
  TempDir dir;
  std::string finished, interrupted;
  std::vector<std::string> queued;
  std::string finished_png;
  {
    ServerProcess server(dir.path());
    auto c = server.client();
    finished = submit(*c, tiny_scene(8, 8, 1));
    wait_for_state(*c, finished, {"succeeded"});
    finished_png = c->Get(("/v1/jobs/" + finished + "/result").c_str())->body;
    // Long enough to be mid-render at the kill, short enough to finish after the restart.
    interrupted = submit(*c, tiny_scene(48, 48, 1024));
    for (int i = 0; i < 5; ++i) queued.push_back(submit(*c, tiny_scene(8, 8, 1)));
    ASSERT_EQ(wait_for_state(*c, interrupted, {"running"})["state"], "running");
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    server.signal(SIGKILL);
    EXPECT_EQ(server.wait_exit(std::chrono::seconds(5)), 128 + SIGKILL);
  }
  ServerProcess server(dir.path());
  auto c = server.client();
  // The finished result is still served, byte for byte.
  EXPECT_EQ(c->Get(("/v1/jobs/" + finished + "/result").c_str())->body, finished_png);
  // The interrupted render runs again, then the queue in order.
  const Json again = wait_for_state(*c, interrupted, {"succeeded", "failed"}, std::chrono::seconds(120));
  EXPECT_EQ(again["state"], "succeeded") << again.dump();
  EXPECT_EQ(again["attempts"], 2) << "counted once before the kill, once after";
  for (const auto& id : queued) {
    const Json job = wait_for_state(*c, id, {"succeeded", "failed"});
    EXPECT_EQ(job["state"], "succeeded") << id;
    EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result").c_str())->status, 200);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/results/" + interrupted + ".png.tmp"));
}

TEST(Durability, EveryAcceptedJobSurvivesAKillRightAfterTheAnswer) {
  TempDir dir;
  std::vector<std::string> accepted;
  {
    ServerProcess server(dir.path(), {"--max-queue", "1000"});
    auto c = server.client();
    submit(*c, long_scene());  // keeps the worker busy so the rest stays queued
    for (int i = 0; i < 30; ++i) accepted.push_back(submit(*c, tiny_scene(8, 8, 1)));
    server.signal(SIGKILL);  // straight after the last 202
    server.wait_exit(std::chrono::seconds(5));
  }
  ServerProcess server(dir.path(), {"--max-queue", "1000"});
  auto c = server.client();
  for (const auto& id : accepted) {
    auto res = c->Get(("/v1/jobs/" + id).c_str());
    ASSERT_EQ(res->status, 200) << id << " was answered 202 and then lost";
  }
  // Cancel the long one; the rest run in order.
  const Json page = Json::parse(c->Get("/v1/jobs?state=running")->body);
  for (const auto& j : page["jobs"]) c->Delete(("/v1/jobs/" + j["id"].get<std::string>()).c_str());
  EXPECT_EQ(wait_for_state(*c, accepted.back(), {"succeeded"})["state"], "succeeded");
}

TEST(Durability, FinishedJobsExpireAfterTheRetention) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--retention", "1s"});
  auto c = server.client();
  const std::string id = submit(*c, tiny_scene(8, 8, 1));
  wait_for_state(*c, id, {"succeeded"});
  EXPECT_TRUE(std::filesystem::exists(dir.path() + "/results/" + id + ".png"));
  int status = 200;
  for (int i = 0; i < 100 && status == 200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    status = c->Get(("/v1/jobs/" + id).c_str())->status;
  }
  EXPECT_EQ(status, 404);
  // The record goes first (the 404), the files once its erase is committed.
  for (int i = 0; i < 100 && std::filesystem::exists(dir.path() + "/results/" + id + ".png"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/results/" + id + ".png"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/results/" + id + ".exr"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/scenes/" + id + ".json"));
}

}  // namespace
}  // namespace penumbra::test
