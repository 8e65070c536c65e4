// Cancelling queued and running jobs; the progressive preview of a running render.
#include <gtest/gtest.h>

#include "server_process.h"

namespace penumbra::test {
namespace {

TEST(Cancel, QueuedJobNeverRuns) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string running = submit(*c, long_scene());
  const std::string queued = submit(*c, tiny_scene());
  wait_for_state(*c, running, {"running"});
  auto res = c->Delete(("/v1/jobs/" + queued).c_str());
  ASSERT_EQ(res->status, 200);
  const Json job = Json::parse(res->body);
  EXPECT_EQ(job["state"], "cancelled");
  EXPECT_TRUE(job["started_at"].is_null());
  EXPECT_EQ(job["attempts"], 0);
  EXPECT_EQ(c->Delete(("/v1/jobs/" + running).c_str())->status, 200);
  // The worker moves on; the cancelled job stays cancelled.
  EXPECT_EQ(wait_for_state(*c, queued, {"running", "succeeded"}, std::chrono::milliseconds(500))["state"],
            "cancelled");
}

TEST(Cancel, RunningRenderStopsWithinAboutATile) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string id = submit(*c, long_scene());
  const Json running = wait_for_state(*c, id, {"running"});
  ASSERT_EQ(running["state"], "running");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto start = std::chrono::steady_clock::now();
  auto res = c->Delete(("/v1/jobs/" + id).c_str());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(Json::parse(res->body)["state"], "cancelled");
  EXPECT_LT(seconds, 1.0) << "cancel took " << seconds << " s";
  // Cancelled: DELETE again removes it; once more is still fine.
  EXPECT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status, 204);
  EXPECT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status, 204);
  EXPECT_EQ(c->Get(("/v1/jobs/" + id).c_str())->status, 404);
}

TEST(Preview, RunningJobServesItsProgressiveImage) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string id = submit(*c, long_scene());
  wait_for_state(*c, id, {"running"});
  auto preview = c->Get(("/v1/jobs/" + id + "/result?preview=true").c_str());
  for (int i = 0; i < 200 && !(preview && preview->status == 200); ++i) {
    // The first pass (1 spp of 64x64) takes milliseconds.
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    preview = c->Get(("/v1/jobs/" + id + "/result?preview=true").c_str());
  }
  ASSERT_TRUE(preview);
  ASSERT_EQ(preview->status, 200) << preview->body;
  EXPECT_EQ(preview->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(preview->get_header_value("Cache-Control"), "no-store");
  EXPECT_EQ(preview->body.compare(0, 4, "\x89PNG"), 0);
  auto exr = c->Get(("/v1/jobs/" + id + "/result?preview=true&format=exr").c_str());
  EXPECT_EQ(exr->status, 200);
  const Json job = get_job(*c, id);
  EXPECT_EQ(job["state"], "running");
  EXPECT_GT(job["progress"].get<double>(), 0.0);
  EXPECT_GT(job["samples_done"].get<uint64_t>(), 0u);
  EXPECT_TRUE(job["eta_seconds"].is_number());
  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result").c_str())->status, 409) << "without preview: not ready";
  c->Delete(("/v1/jobs/" + id).c_str());
}

}  // namespace
}  // namespace penumbra::test
