// A bounded load test: several client threads, hundreds of submits and thousands of status
// polls (fixed counts), while a render runs. Checks that nothing is lost and every answer is
// right, and reports the status-poll latency (p50/p99), the figure quoted in docs/http-api.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <set>

#include "server_process.h"

namespace penumbra::test {
namespace {

constexpr int kClients = 4;
constexpr int kSubmitsPerClient = 50;
constexpr int kPollsPerClient = 750;

int state_rank(const std::string& s) {
  if (s == "queued") return 0;
  if (s == "running") return 1;
  if (s == "succeeded") return 2;
  return -1;
}

TEST(Load, HundredsOfSubmitsThousandsOfPollsNothingLost) {
  TempDir dir;
  // Two workers of one thread each: one keeps the long render going, the other takes the
  // small jobs; HTTP threads compete with both for the machine's cores.
  ServerProcess server(dir.path(), {"--workers", "2", "--render-threads", "1", "--max-queue", "1000",
                                    "--http-threads", "8"});
  auto c = server.client();
  Json background = long_scene();
  background["render"]["time_limit"] = 60;
  const std::string background_id = submit(*c, background);
  ASSERT_EQ(wait_for_state(*c, background_id, {"running"})["state"], "running");

  std::mutex mutex;
  std::vector<double> poll_ms;
  std::set<std::string> accepted;
  std::atomic<int> wrong_answers{0};
  std::vector<std::string> errors;
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> clients;
  for (int t = 0; t < kClients; ++t) {
    clients.emplace_back([&, t] {
      auto client = server.client();
      std::vector<std::string> mine;
      std::map<std::string, int> last_rank;
      std::vector<double> latencies;
      auto wrong = [&](const std::string& what) {
        ++wrong_answers;
        std::lock_guard lock(mutex);
        if (errors.size() < 10) errors.push_back(what);
      };
      const int polls_per_submit = kPollsPerClient / kSubmitsPerClient;
      for (int i = 0; i < kSubmitsPerClient; ++i) {
        Json scene = tiny_scene(8, 8, 1);
        scene["render"]["seed"] = t * 1000 + i;
        auto res = post_json(*client, "/v1/jobs", scene.dump());
        if (!res || res->status != 202) {
          wrong("submit: " + (res ? std::to_string(res->status) : std::string("no answer")));
          continue;
        }
        const Json job = Json::parse(res->body);
        if (res->get_header_value("Location") != "/v1/jobs/" + job["id"].get<std::string>())
          wrong("Location mismatch");
        mine.push_back(job["id"]);
        for (int k = 0; k < polls_per_submit; ++k) {
          const std::string& id = mine[std::size_t(k * 7 + i) % mine.size()];
          const auto t0 = std::chrono::steady_clock::now();
          auto poll = client->Get(("/v1/jobs/" + id).c_str());
          latencies.push_back(
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
          if (!poll || poll->status != 200) {
            wrong("poll: " + (poll ? std::to_string(poll->status) : std::string("no answer")));
            continue;
          }
          const Json p = Json::parse(poll->body);
          const int rank = state_rank(p["state"]);
          if (p["id"] != id || rank < 0 || rank < last_rank[id]) wrong("poll answer: " + poll->body);
          last_rank[id] = std::max(last_rank[id], rank);
          if (rank < 2 && !poll->has_header("Retry-After")) wrong("no Retry-After while unfinished");
        }
      }
      std::lock_guard lock(mutex);
      poll_ms.insert(poll_ms.end(), latencies.begin(), latencies.end());
      accepted.insert(mine.begin(), mine.end());
    });
  }
  for (auto& t : clients) t.join();
  const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(get_job(*c, background_id)["state"], "running") << "the polls ran while a render ran";
  EXPECT_EQ(wrong_answers.load(), 0) << (errors.empty() ? "" : errors.front());
  ASSERT_EQ(accepted.size(), std::size_t(kClients * kSubmitsPerClient));
  ASSERT_EQ(poll_ms.size(), std::size_t(kClients * kPollsPerClient));

  std::sort(poll_ms.begin(), poll_ms.end());
  const double p50 = poll_ms[poll_ms.size() / 2];
  const double p99 = poll_ms[poll_ms.size() * 99 / 100];
  std::printf("load: %d submits + %zu status polls from %d clients in %.2f s while a render ran; "
              "poll latency p50 %.2f ms, p99 %.2f ms, max %.2f ms\n",
              kClients * kSubmitsPerClient, poll_ms.size(), kClients, load_seconds, p50, p99, poll_ms.back());
  RecordProperty("poll_p50_ms", std::to_string(p50));
  RecordProperty("poll_p99_ms", std::to_string(p99));
  EXPECT_LT(p99, 250.0) << "polls must not wait for renders";

  // Every accepted job finishes, and the listing holds exactly them (plus the background).
  c->Delete(("/v1/jobs/" + background_id).c_str());
  for (const auto& id : accepted) {
    const Json job = wait_for_state(*c, id, {"succeeded", "failed", "cancelled"}, std::chrono::seconds(120));
    ASSERT_EQ(job["state"], "succeeded") << job.dump();
  }
  std::set<std::string> listed;
  std::string token;
  for (int page = 0; page < 10; ++page) {
    const Json p = Json::parse(c->Get(("/v1/jobs?limit=100" + (token.empty() ? "" : "&page_token=" + token)).c_str())->body);
    for (const auto& j : p["jobs"]) listed.insert(j["id"].get<std::string>());
    if (p["next_page_token"].is_null()) break;
    token = p["next_page_token"];
  }
  listed.erase(background_id);
  EXPECT_EQ(listed, accepted);
  const std::string metrics = c->Get("/metrics")->body;
  EXPECT_NE(metrics.find("penumbra_jobs{state=\"succeeded\"} " + std::to_string(accepted.size())), std::string::npos);
}

}  // namespace
}  // namespace penumbra::test
