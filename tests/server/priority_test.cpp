// Job priorities through the real binary: higher first, FIFO within a priority, shown in
// GET /v1/jobs?state=queued (run order, paged) and each job's queue_position, kept across a
// kill -9; out-of-range priorities are refused with their pointer.
#include <gtest/gtest.h>

#include "server_process.h"

namespace penumbra::test {
namespace {

Json with_priority(Json scene, int priority) {
  scene["priority"] = priority;
  return scene;
}

std::vector<std::string> queued_ids(httplib::Client& c, int limit = 100) {
  std::vector<std::string> ids;
  std::string token;
  for (;;) {
    std::string path = "/v1/jobs?state=queued&limit=" + std::to_string(limit);
    if (!token.empty()) path += "&page_token=" + token;
    auto res = c.Get(path.c_str());
    if (!res || res->status != 200) throw std::runtime_error("list: " + (res ? res->body : ""));
    const Json page = Json::parse(res->body);
    for (const Json& j : page["jobs"]) ids.push_back(j["id"]);
    if (page["next_page_token"].is_null()) return ids;
    token = page["next_page_token"];
  }
}

TEST(Priority, HigherFirstFifoWithinAPriorityListedInRunOrderAndKeptAcrossKill9) {
  TempDir dir;
  std::vector<std::string> expected;
  std::string blocker_id;
  {
    ServerProcess server(dir.path(), {"--workers", "1"});
    auto c = server.client();
    const std::string blocker = submit(*c, long_scene());
    wait_for_state(*c, blocker, {"running"});
    blocker_id = blocker;
    const std::string low = submit(*c, with_priority(tiny_scene(), -5));
    const std::string mid_a = submit(*c, tiny_scene());  // default 0
    const std::string high = submit(*c, with_priority(tiny_scene(), 10));
    const std::string mid_b = submit(*c, with_priority(tiny_scene(), 0));
    const std::string top = submit(*c, with_priority(tiny_scene(), 1000));
    expected = {top, high, mid_a, mid_b, low};
    EXPECT_EQ(queued_ids(*c), expected);
    EXPECT_EQ(queued_ids(*c, 2), expected) << "paging in run order";
    for (std::size_t i = 0; i < expected.size(); ++i) {
      const Json job = get_job(*c, expected[i]);
      EXPECT_EQ(job["queue_position"], i);
    }
    EXPECT_EQ(get_job(*c, high)["priority"], 10);
    EXPECT_EQ(get_job(*c, mid_a)["priority"], 0);
    server.signal(SIGKILL);
    server.wait_exit(std::chrono::seconds(10));
  }
  ServerProcess again(dir.path(), {"--workers", "1"});
  auto c = again.client();
  // The interrupted blocker (priority 0, oldest of the 0s) would run third: cancel it.
  EXPECT_EQ(c->Delete(("/v1/jobs/" + blocker_id).c_str())->status, 200);
  for (const std::string& id : expected) {
    const Json done = wait_for_state(*c, id, {"succeeded", "failed"}, std::chrono::seconds(120));
    ASSERT_EQ(done["state"], "succeeded");
  }
  // They ran in run order after the restart too: started_at (RFC 3339, sortable) follows it.
  std::vector<std::string> started;
  for (const std::string& id : expected) started.push_back(get_job(*c, id)["started_at"]);
  EXPECT_TRUE(std::is_sorted(started.begin(), started.end())) << "ran in priority order";
}

TEST(Priority, OutOfRangeOrNotAnIntegerIsRefusedWithItsPointer) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  for (const Json& bad : {Json(1001), Json(-1001), Json(1.5), Json("high"), Json(nullptr)}) {
    Json scene = tiny_scene();
    scene["priority"] = bad;
    auto res = post_json(*c, "/v1/jobs", scene.dump());
    ASSERT_EQ(res->status, 422) << bad.dump();
    const Json p = Json::parse(res->body);
    EXPECT_EQ(p["errors"][0]["pointer"], "/priority") << res->body;
  }
  for (int ok : {-1000, 1000}) EXPECT_NO_THROW(submit(*c, with_priority(tiny_scene(), ok)));
  // A bad token for the run-order listing.
  EXPECT_EQ(c->Get("/v1/jobs?state=queued&page_token=xyz")->status, 400);
}

}  // namespace
}  // namespace penumbra::test
