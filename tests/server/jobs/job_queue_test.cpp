// The FIFO of queued job ids: order, capacity, removal (cancel), positions, close.
#include "server/jobs/job_queue.h"

#include <gtest/gtest.h>

#include <future>

namespace penumbra::test {
namespace {

using server::JobQueue;
using namespace std::chrono_literals;

TEST(JobQueue, FirstInFirstOut) {
  JobQueue q(10);
  for (const char* id : {"a", "b", "c"}) q.push(id);
  EXPECT_EQ(q.pop(), "a");
  EXPECT_EQ(q.pop(), "b");
  q.push("d");
  EXPECT_EQ(q.pop(), "c");
  EXPECT_EQ(q.pop(), "d");
  EXPECT_EQ(q.size(), 0u);
}

TEST(JobQueue, CapacityAtTheBoundaryAndForcedPushes) {
  JobQueue q(2);
  EXPECT_EQ(q.push("a"), JobQueue::PushResult::kPushed);
  EXPECT_FALSE(q.full());
  EXPECT_EQ(q.push("b"), JobQueue::PushResult::kPushed);
  EXPECT_TRUE(q.full());
  EXPECT_EQ(q.push("c"), JobQueue::PushResult::kFull);
  EXPECT_EQ(q.push("c", /*force=*/true), JobQueue::PushResult::kPushed)
      << "recovered jobs were accepted";
  EXPECT_EQ(q.size(), 3u);
}

TEST(JobQueue, RemovingAQueuedJobMovesTheOnesBehindIt) {
  JobQueue q(10);
  for (const char* id : {"a", "b", "c"}) q.push(id);
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
  EXPECT_EQ(q.push("a"), JobQueue::PushResult::kClosed);
}

}  // namespace
}  // namespace penumbra::test
