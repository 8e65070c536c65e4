// The queue of job ids: run order (priority, then FIFO), capacity, removal (cancel), positions,
// close.
#include "server/jobs/job_queue.h"

#include <gtest/gtest.h>

#include <future>

namespace penumbra::test {
namespace {

using server::JobQueue;
using namespace std::chrono_literals;

TEST(JobQueue, FirstInFirstOut) {
  JobQueue q(10);
  int64_t seq = 0;
  for (const char* id : {"a", "b", "c"}) q.push(id, 0, ++seq);
  EXPECT_EQ(q.pop(), "a");
  EXPECT_EQ(q.pop(), "b");
  q.push("d", 0, ++seq);
  EXPECT_EQ(q.pop(), "c");
  EXPECT_EQ(q.pop(), "d");
  EXPECT_EQ(q.size(), 0u);
}

TEST(JobQueue, CapacityAtTheBoundaryAndForcedPushes) {
  JobQueue q(2);
  EXPECT_EQ(q.push("a", 0, 1), JobQueue::PushResult::kPushed);
  EXPECT_FALSE(q.full());
  EXPECT_EQ(q.push("b", 0, 2), JobQueue::PushResult::kPushed);
  EXPECT_TRUE(q.full());
  EXPECT_EQ(q.push("c", 9, 3), JobQueue::PushResult::kFull) << "priority does not pass the cap";
  EXPECT_EQ(q.push("c", 0, 3, /*force=*/true), JobQueue::PushResult::kPushed)
      << "recovered jobs were accepted";
  EXPECT_EQ(q.size(), 3u);
}

TEST(JobQueue, HigherPriorityFirstAndFirstInFirstOutWithinAPriority) {
  JobQueue q(10);
  // seq is the submission order; pushes arrive out of it as at a restart.
  q.push("low-old", -5, 1);
  q.push("mid-new", 0, 6);
  q.push("high", 10, 4);
  q.push("mid-old", 0, 2);
  q.push("mid-mid", 0, 3);
  q.push("low-new", -5, 5);
  EXPECT_EQ(q.position("high"), 0u);
  EXPECT_EQ(q.position("mid-old"), 1u);
  EXPECT_EQ(q.position("low-new"), 5u);
  for (const char* id : {"high", "mid-old", "mid-mid", "mid-new", "low-old", "low-new"})
    EXPECT_EQ(q.pop(), id);
}

TEST(JobQueue, RemovingAQueuedJobMovesTheOnesBehindIt) {
  JobQueue q(10);
  int64_t seq = 0;
  for (const char* id : {"a", "b", "c"}) q.push(id, 0, ++seq);
  EXPECT_EQ(q.position("c"), 2u);
  EXPECT_TRUE(q.remove("b"));
  EXPECT_FALSE(q.remove("b"));
  EXPECT_FALSE(q.position("b"));
  EXPECT_EQ(q.position("a"), 0u);
  EXPECT_EQ(q.position("c"), 1u);
  EXPECT_EQ(q.pop(), "a");
  EXPECT_EQ(q.pop(), "c");
}

TEST(JobQueue, CloseWakesAWaitingWorkerAndRefusesPushes) {
  JobQueue q(10);
  auto waiting = std::async(std::launch::async, [&] { return q.pop(); });
  EXPECT_EQ(waiting.wait_for(50ms), std::future_status::timeout) << "pop blocks on an empty queue";
  q.close();
  ASSERT_EQ(waiting.wait_for(5s), std::future_status::ready);
  EXPECT_FALSE(waiting.get());
  EXPECT_EQ(q.push("a", 0, 1), JobQueue::PushResult::kClosed);
}

}  // namespace
}  // namespace penumbra::test
