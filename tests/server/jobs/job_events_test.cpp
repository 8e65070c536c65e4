// The per-job event history behind GET /v1/jobs/{id}/events: ids, what is kept, resuming,
// progress coalescing and rate, forgetting, waiting.
#include "server/jobs/job_events.h"

#include <gtest/gtest.h>

#include <future>
#include <thread>

namespace penumbra::test {
namespace {

using namespace server;
using namespace std::chrono_literals;

JobRecord record(const std::string& id, JobState state) {
  JobRecord r;
  r.id = id;
  r.state = state;
  return r;
}

RenderProgress progress(uint64_t samples) {
  RenderProgress p;
  p.samples_done = samples;
  p.fraction = double(samples) / 100.0;
  return p;
}

TEST(JobEvents, IdsIncreaseAcrossJobsAndStartAboveTheClock) {
  JobEvents events;
  const uint64_t a = events.record_change(record("a", JobState::kQueued), 0);
  const uint64_t b = events.record_change(record("b", JobState::kQueued), 1);
  const uint64_t a2 = events.record_change(record("a", JobState::kRunning), std::nullopt);
  EXPECT_LT(a, b);
  EXPECT_LT(b, a2);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::system_clock::now().time_since_epoch()).count();
  EXPECT_GE(a, uint64_t(ms - 60'000) * 1024) << "a restart starts above the last run's ids";
  std::this_thread::sleep_for(2ms);  // a restart takes far longer than the 1024 ids of one ms
  JobEvents later;
  EXPECT_GT(later.record_change(record("a", JobState::kQueued), 0), a2);
}

TEST(JobEvents, ResumeGetsTheEventsAfterAnIdAndProgressIsCoalesced) {
  JobEvents events;
  const uint64_t q = events.record_change(record("a", JobState::kQueued), 0);
  const uint64_t r = events.record_change(record("a", JobState::kRunning), std::nullopt);
  std::this_thread::sleep_for(JobEvents::kProgressInterval);
  events.sample_progress(record("a", JobState::kRunning), progress(10));
  events.sample_progress(record("a", JobState::kRunning), progress(20));  // too soon: dropped
  auto after = events.after("a", r);
  ASSERT_EQ(after.size(), 1u);
  EXPECT_TRUE(after[0].progress_only);
  EXPECT_EQ(after[0].progress->samples_done, 10u);
  std::this_thread::sleep_for(JobEvents::kProgressInterval);
  events.sample_progress(record("a", JobState::kRunning), progress(10));  // unchanged: dropped
  EXPECT_EQ(events.after("a", r).size(), 1u);
  events.sample_progress(record("a", JobState::kRunning), progress(30));
  after = events.after("a", r);
  ASSERT_EQ(after.size(), 1u) << "only the latest progress is kept";
  EXPECT_EQ(after[0].progress->samples_done, 30u);
  const uint64_t done = events.record_change(record("a", JobState::kSucceeded), std::nullopt);
  after = events.after("a", q);
  ASSERT_EQ(after.size(), 2u) << "a finished job keeps its state changes";
  EXPECT_EQ(after[0].id, r);
  EXPECT_EQ(after[1].id, done);
  EXPECT_TRUE(events.after("a", done).empty());
  EXPECT_EQ(events.latest_id(record("a", JobState::kSucceeded), std::nullopt), done);
}

TEST(JobEvents, HistoryIsBoundedAndForgottenWithTheJob) {
  JobEvents events;
  for (std::size_t i = 0; i < JobEvents::kMaxEventsPerJob + 10; ++i)
    events.record_change(record("a", i % 2 ? JobState::kRunning : JobState::kQueued), 0);
  EXPECT_EQ(events.after("a", 0).size(), JobEvents::kMaxEventsPerJob);
  events.record_change(record("a", JobState::kDeleted), std::nullopt);
  EXPECT_TRUE(events.after("a", 0).empty());
  events.record_change(record("b", JobState::kQueued), 0);
  events.forget("b");
  EXPECT_TRUE(events.after("b", 0).empty());
  // A job with no history gets one from latest_id (after a restart).
  const uint64_t id = events.latest_id(record("c", JobState::kSucceeded), std::nullopt);
  ASSERT_EQ(events.after("c", 0).size(), 1u);
  EXPECT_EQ(events.after("c", 0)[0].id, id);
}

TEST(JobEvents, WaitWakesOnAnEventAndOnWakeAll) {
  JobEvents events;
  const uint64_t q = events.record_change(record("a", JobState::kQueued), 0);
  auto waiter = std::async(std::launch::async, [&] {
    events.wait("a", q, std::chrono::steady_clock::now() + 10s);
    return events.after("a", q).size();
  });
  EXPECT_EQ(waiter.wait_for(50ms), std::future_status::timeout);
  events.record_change(record("a", JobState::kRunning), std::nullopt);
  ASSERT_EQ(waiter.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(waiter.get(), 1u);
  auto woken = std::async(std::launch::async, [&] {
    events.wait("a", UINT64_MAX, std::chrono::steady_clock::now() + 10s);
  });
  EXPECT_EQ(woken.wait_for(50ms), std::future_status::timeout);
  events.wake_all();
  EXPECT_EQ(woken.wait_for(5s), std::future_status::ready);
  EXPECT_TRUE(events.try_open_stream(1));
  EXPECT_FALSE(events.try_open_stream(1));
  events.close_stream();
  EXPECT_TRUE(events.try_open_stream(1));
}

}  // namespace
}  // namespace penumbra::test
