// The store writer: a ticket is waited for until its commit is on disk, changes keep their
// order across commits, a burst shares one commit, and a failed commit reaches its waiter and
// the log instead of vanishing.
#include "server/jobs/store_writer.h"

#include <gtest/gtest.h>

#include <future>

#include "server/storage/sqlite_job_store.h"
#include "tests/server/jobs/gated_stores.h"
#include "tests/server/test_support.h"

namespace penumbra::test {
namespace {

using server::InsertJob;
using server::JobRecord;
using server::StoreWriter;
using server::UpdateJob;
using namespace std::chrono_literals;

JobRecord job(const std::string& id, int64_t seq) {
  JobRecord r;
  r.id = id;
  r.seq = seq;
  r.created_at = 1.0;
  return r;
}

TEST(StoreWriter, DurableMeansCommitted) {
  TempDir dir;
  server::SqliteJobStore sqlite(dir.path() + "/jobs.db");
  Gate gate;
  GatedJobStore store(sqlite, gate);
  StoreWriter writer(store);
  gate.close();
  const StoreWriter::Ticket t = writer.enqueue(InsertJob{job("a", 1), "{}"});
  auto waiting = std::async(std::launch::async, [&] { writer.wait_durable(t); });
  ASSERT_TRUE(gate.wait_arrived(1));
  EXPECT_EQ(waiting.wait_for(100ms), std::future_status::timeout) << "returned before the commit";
  gate.open();
  ASSERT_EQ(waiting.wait_for(10s), std::future_status::ready);
  EXPECT_EQ(sqlite.load().records.size(), 1u);
}

TEST(StoreWriter, ABurstKeepsItsOrderAndSharesACommit) {
  TempDir dir;
  server::SqliteJobStore sqlite(dir.path() + "/jobs.db");
  Gate gate;
  GatedJobStore store(sqlite, gate);
  StoreWriter writer(store);
  gate.close();
  writer.enqueue(InsertJob{job("a", 1), "{}"});
  ASSERT_TRUE(gate.wait_arrived(1));  // the first commit is under way; the rest queue up
  JobRecord r = job("a", 1);
  for (int i = 1; i <= 50; ++i) {
    r.attempts = i;
    writer.enqueue(UpdateJob{r});
  }
  gate.open();
  writer.flush();
  EXPECT_EQ(sqlite.load().records.at(0).attempts, 50) << "the last change is the one stored";
  EXPECT_EQ(gate.arrived(), 2) << "50 queued changes, one commit";
}

TEST(StoreWriter, AFailedCommitReachesItsWaiterAndTheLog) {
  TempDir dir;
  server::SqliteJobStore sqlite(dir.path() + "/jobs.db");
  StoreWriter writer(sqlite);
  writer.wait_durable(writer.enqueue(InsertJob{job("a", 1), "{}"}));
  ::testing::internal::CaptureStderr();
  const StoreWriter::Ticket duplicate = writer.enqueue(InsertJob{job("a", 2), "{}"});
  EXPECT_THROW(writer.wait_durable(duplicate), server::StoreError);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("insert a"), std::string::npos) << log;
  EXPECT_NE(log.find("failed"), std::string::npos) << log;
  // Later changes are not blamed for it.
  EXPECT_NO_THROW(writer.wait_durable(writer.enqueue(InsertJob{job("b", 3), "{}"})));
}

}  // namespace
}  // namespace penumbra::test
