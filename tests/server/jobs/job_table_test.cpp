// The in-memory job table: listings newest first with paging and filters, the idempotency-key
// index following tombstones, expiry, and every change reaching the store in order.
#include "server/jobs/job_table.h"

#include <gtest/gtest.h>

#include "server/storage/sqlite_job_store.h"
#include "tests/server/test_support.h"

namespace penumbra::test {
namespace {

using server::JobEntry;
using server::JobRecord;
using server::JobState;

JobRecord job(int seq, JobState state, const std::string& key = "") {
  JobRecord r;
  r.id = "job" + std::to_string(seq);
  r.seq = seq;
  r.state = state;
  r.idempotency_key = key;
  r.created_at = 100 + seq;
  r.finished_at = server::is_finished(state) ? 200 + seq : 0;
  return r;
}

std::vector<std::string> ids(const std::vector<JobEntry>& entries) {
  std::vector<std::string> out;
  for (const auto& e : entries) out.push_back(e.record.id);
  return out;
}

TEST(JobTable, ListsNewestFirstPageByPage) {
  TempDir dir;
  server::SqliteJobStore store(dir.path() + "/jobs.db");
  server::StoreWriter writer(store);
  server::JobTable table(writer);
  table.restore({job(3, JobState::kSucceeded), job(1, JobState::kQueued),
                 job(2, JobState::kDeleted), job(5, JobState::kQueued), job(4, JobState::kFailed)});
  using V = std::vector<std::string>;
  EXPECT_EQ(ids(table.list(std::nullopt, 0, 10)), (V{"job5", "job4", "job3", "job1"}))
      << "no tombstones";
  EXPECT_EQ(ids(table.list(std::nullopt, 0, 2)), (V{"job5", "job4"}));
  EXPECT_EQ(ids(table.list(std::nullopt, 4, 2)), (V{"job3", "job1"})) << "the page after seq 4";
  EXPECT_EQ(ids(table.list(JobState::kQueued, 0, 10)), (V{"job5", "job1"}));
  EXPECT_EQ(table.count_by_state()[JobState::kQueued], 2);
}

TEST(JobTable, RestoreRequeuesInterruptedJobsInSeqOrder) {
  TempDir dir;
  server::SqliteJobStore store(dir.path() + "/jobs.db");
  server::StoreWriter writer(store);
  server::JobTable table(writer);
  const auto queued = table.restore({job(3, JobState::kQueued), job(1, JobState::kRunning),
                                     job(2, JobState::kSucceeded), job(4, JobState::kRunning)});
  EXPECT_EQ(queued, (std::vector<std::string>{"job1", "job3", "job4"}));
  EXPECT_EQ(table.find("job1")->record.state, JobState::kQueued);
}

TEST(JobTable, TheKeyIndexFollowsChangesAndEveryChangeIsStoredInOrder) {
  TempDir dir;
  server::SqliteJobStore store(dir.path() + "/jobs.db");
  server::StoreWriter writer(store);
  server::JobTable table(writer);
  const JobRecord r = job(1, JobState::kSucceeded, "key");
  writer.wait_durable(writer.enqueue(server::InsertJob{r, "{}"}));
  table.add(r);
  ASSERT_TRUE(table.find_by_key("key"));
  for (int attempt = 1; attempt <= 3; ++attempt)
    table.modify("job1", [&](JobEntry& e) {
      e.record.attempts = attempt;
      return true;
    });
  EXPECT_FALSE(table.modify("job1", [](JobEntry&) { return false; }))
      << "no change, nothing queued";
  EXPECT_FALSE(table.modify("nope", [](JobEntry&) { return true; }));
  const auto ticket = table.modify("job1", [](JobEntry& e) {
    e.record.state = JobState::kDeleted;
    e.record.idempotency_key.clear();
    return true;
  });
  ASSERT_TRUE(ticket);
  writer.wait_durable(*ticket);
  EXPECT_FALSE(table.find_by_key("key")) << "a tombstone frees its key";
  const JobRecord stored = store.load().records.at(0);
  EXPECT_EQ(stored.state, JobState::kDeleted);
  EXPECT_EQ(stored.attempts, 3);
}

TEST(JobTable, ExpiryTakesFinishedJobsAndTombstonesOnly) {
  TempDir dir;
  server::SqliteJobStore store(dir.path() + "/jobs.db");
  server::StoreWriter writer(store);
  server::JobTable table(writer);
  table.restore({job(1, JobState::kSucceeded), job(2, JobState::kQueued),
                 job(3, JobState::kCancelled), job(4, JobState::kFailed)});
  // finished_at is 200 + seq: jobs 1 and 3 are older than 203.5.
  auto expired = table.take_expired(203.5);
  std::sort(expired.begin(), expired.end());
  EXPECT_EQ(expired, (std::vector<std::string>{"job1", "job3"}));
  EXPECT_FALSE(table.find("job1"));
  EXPECT_TRUE(table.find("job2")) << "a queued job never expires";
  EXPECT_TRUE(table.find("job4"));
}

}  // namespace
}  // namespace penumbra::test
