// SIGTERM/SIGINT: /readyz turns 503, no new jobs, the running render goes back to the queue,
// and the process exits well inside 30 s.
#include <gtest/gtest.h>

#include <csignal>

#include "server_process.h"

namespace penumbra::test {
namespace {

void shutdown_during_render(int sig) {
  TempDir dir;
  std::string running, queued;
  {
    ServerProcess server(dir.path(), {"--drain", "1500ms"});
    auto c = server.client();
    running = submit(*c, long_scene());
    queued = submit(*c, tiny_scene(8, 8, 1));
    ASSERT_EQ(wait_for_state(*c, running, {"running"})["state"], "running");
    const auto start = std::chrono::steady_clock::now();
    server.signal(sig);
    // During the drain the port still answers, but not ready and no new work.
    bool saw_not_ready = false;
    int post_status = 0;
    for (int i = 0; i < 100 && !saw_not_ready; ++i) {
      auto ready = server.client()->Get("/readyz");
      if (ready && ready->status == 503) {
        saw_not_ready = true;
        EXPECT_FALSE(ready->get_header_value("Retry-After").empty());
        auto post = post_json(*server.client(), "/v1/jobs", tiny_scene().dump());
        post_status = post ? post->status : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_TRUE(saw_not_ready);
    EXPECT_EQ(post_status, 503);
    const int code = server.wait_exit(std::chrono::seconds(30));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(code, 0);
    EXPECT_LT(seconds, 10.0) << "shutdown took " << seconds << " s";
  }
  // After the restart the interrupted job is queued again, first in line, and not counted as
  // a crashed attempt.
  ServerProcess server(dir.path());
  auto c = server.client();
  const Json again = wait_for_state(*c, running, {"running"});
  EXPECT_EQ(again["state"], "running");
  EXPECT_EQ(again["attempts"], 1);
  EXPECT_EQ(get_job(*c, queued)["state"], "queued");
  c->Delete(("/v1/jobs/" + running).c_str());
  EXPECT_EQ(wait_for_state(*c, queued, {"succeeded"})["state"], "succeeded");
}

TEST(GracefulShutdown, SigtermRequeuesTheRunningRender) { shutdown_during_render(SIGTERM); }
TEST(GracefulShutdown, SigintToo) { shutdown_during_render(SIGINT); }

TEST(GracefulShutdown, IdleServerExitsPromptly) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--drain", "0s"});
  const auto start = std::chrono::steady_clock::now();
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait_exit(std::chrono::seconds(10)), 0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 3.0);
}

}  // namespace
}  // namespace penumbra::test
