// GET /v1/workers on one node: its render slots and the jobs they render (the farm's workers are
// tested against PostgreSQL in tests/farm/farm_test.py).
#include <gtest/gtest.h>

#include "server_process.h"

namespace penumbra::test {
namespace {

TEST(WorkersRoute, OneNodeShowsItsSlotsAndTheRunningJob) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--workers", "2", "--render-threads", "1"});
  auto c = server.client();
  auto idle = c->Get("/v1/workers");
  ASSERT_TRUE(idle);
  ASSERT_EQ(idle->status, 200);
  const Json before = Json::parse(idle->body);
  ASSERT_EQ(before["workers"].size(), 1u);
  EXPECT_EQ(before["workers"][0]["slots"], 2);
  EXPECT_EQ(before["workers"][0]["render_threads"], 1);
  EXPECT_TRUE(before["workers"][0]["current_tasks"].empty());

  const std::string id = submit(*c, long_scene());
  wait_for_state(*c, id, {"running"});
  auto busy = c->Get("/v1/workers");
  ASSERT_TRUE(busy);
  const Json during = Json::parse(busy->body);
  ASSERT_EQ(during["workers"][0]["current_tasks"].size(), 1u);
  EXPECT_EQ(during["workers"][0]["current_tasks"][0]["job"], id);
  EXPECT_EQ(during["workers"][0]["current_tasks"][0]["kind"], "job");
  c->Delete(("/v1/jobs/" + id).c_str());
}

}  // namespace
}  // namespace penumbra::test
