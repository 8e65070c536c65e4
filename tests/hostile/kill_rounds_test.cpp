// kill -9 during bursts of submissions (issue 15: 15 rounds, 479 accepted jobs, none lost):
// 5 rounds on one data directory, each killing the server while two clients submit; every job
// answered 202 must be there after the restart, and all of them finish. Fixed counts, ~15 s.
#include <gtest/gtest.h>

#include <atomic>
#include <csignal>
#include <mutex>
#include <set>
#include <thread>

#include "hostile_support.h"

namespace penumbra::test {
namespace {

constexpr int kRounds = 5;

TEST(KillRounds, NoAcceptedJobIsLost) {
  TempDir dir;
  std::set<std::string> accepted;
  for (int round = 0; round < kRounds; ++round) {
    ServerProcess server(dir.path(), {"--max-queue", "1000"});
    std::mutex mutex;
    std::atomic<bool> go{true};
    std::vector<std::thread> clients;
    for (int t = 0; t < 2; ++t)
      clients.emplace_back([&] {
        auto c = server.client();
        c->set_read_timeout(2);
        while (go) {
          auto res = post_json(*c, "/v1/jobs", tiny_scene(8, 8, 1).dump());
          if (!res) return;  // killed
          if (res->status == 202) {
            std::lock_guard<std::mutex> lock(mutex);
            accepted.insert(Json::parse(res->body)["id"].get<std::string>());
          }
        }
      });
    // Killed at a different point of the burst each round.
    std::this_thread::sleep_for(std::chrono::milliseconds(150 + 70 * round));
    server.signal(SIGKILL);
    EXPECT_EQ(server.wait_exit(std::chrono::seconds(5)), 128 + SIGKILL);
    go = false;
    for (auto& t : clients) t.join();
  }
  ASSERT_GT(accepted.size(), 20u);
  ServerProcess server(dir.path());
  auto c = server.client();
  int finished = 0;
  for (const std::string& id : accepted) {
    const Json job = wait_for_state(*c, id, {"succeeded", "failed"}, std::chrono::seconds(60));
    EXPECT_EQ(job["state"], "succeeded") << id << " " << job.dump();
    if (job["state"] == "succeeded") ++finished;
  }
  std::printf(
      "[ figures ] %d rounds of kill -9 during submission bursts: %zu jobs accepted, %d "
      "found and finished after restarts\n",
      kRounds, accepted.size(), finished);
}

}  // namespace
}  // namespace penumbra::test
