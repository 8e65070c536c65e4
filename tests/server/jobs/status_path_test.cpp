// A status poll never waits for a disk: while a commit is held open (a gated real SQLite
// store) or a result deletion is (gated real result files), polls and listings still answer
// within milliseconds, and they already show the change being written.
#include <gtest/gtest.h>

#include <future>

#include "tests/server/jobs/service_fixture.h"

namespace penumbra::test {
namespace {

using server::DeleteOutcome;
using server::JobState;
using server::SubmitOutcome;
using namespace std::chrono_literals;

// Far above a poll's microseconds, far below the time the gate is held.
constexpr auto kPollBound = 200ms;

struct PollTimes {
  int polls = 0;
  std::chrono::duration<double, std::milli> slowest{0};
};

// Polls the jobs (and a listing) `rounds` times on another thread. When they have not finished
// within the timeout (a poll blocked behind the gate), opens the gate so the test fails instead
// of hanging, and returns nullopt.
std::optional<PollTimes> poll_on_the_side(server::JobService& s,
                                          const std::vector<std::string>& ids, int rounds,
                                          std::chrono::milliseconds timeout, Gate& gate) {
  auto polls = std::async(std::launch::async, [&s, ids, rounds] {
    PollTimes t;
    for (int i = 0; i < rounds; ++i) {
      for (const auto& id : ids) {
        const auto t0 = std::chrono::steady_clock::now();
        s.view(id);
        t.slowest = std::max(t.slowest, std::chrono::duration<double, std::milli>(
                                            std::chrono::steady_clock::now() - t0));
        ++t.polls;
      }
      s.list(std::nullopt, 0, 20);
    }
    return t;
  });
  if (polls.wait_for(timeout) == std::future_status::ready) return polls.get();
  gate.open();
  polls.wait();
  return std::nullopt;
}

TEST(StatusPath, PollsDoNotWaitForACommitInProgress) {
  TempDir dir;
  Service s(dir.path());
  const std::string finished = submit_ok(*s, tiny_scene(8, 8, 1));
  ASSERT_EQ(wait_for_state(*s, finished, JobState::kSucceeded)->record.state, JobState::kSucceeded);
  const std::string running = submit_ok(*s, long_scene());
  ASSERT_EQ(wait_for_state(*s, running, JobState::kRunning)->record.state, JobState::kRunning);
  const std::string queued = submit_ok(*s, tiny_scene(8, 8, 1));

  // Every commit from now on blocks: a submission, a delete and a cancel all wait for one.
  s.commit_gate.close();
  const int commits_before = s.commit_gate.arrived();
  auto submitting =
      std::async(std::launch::async, [&] { return s->submit(tiny_scene(8, 8, 1).dump(), ""); });
  ASSERT_TRUE(s.commit_gate.wait_arrived(commits_before + 1))
      << "the submission reached its commit";
  auto deleting =
      std::async(std::launch::async, [&] { return s->cancel_or_delete(finished, 3000ms); });
  auto cancelling =
      std::async(std::launch::async, [&] { return s->cancel_or_delete(queued, 3000ms); });
  std::this_thread::sleep_for(
      100ms);  // both are now waiting for durability (or, if buggy, for a lock)

  const auto times = poll_on_the_side(*s, {running, queued, finished}, 200, 5s, s.commit_gate);
  const bool still_committing = deleting.wait_for(0ms) == std::future_status::timeout &&
                                cancelling.wait_for(0ms) == std::future_status::timeout &&
                                submitting.wait_for(0ms) == std::future_status::timeout;
  // The polls saw the changes that were not on disk yet: memory is the authority.
  const auto queued_view = s->view(queued);
  const auto finished_view = s->view(finished);
  s.commit_gate.open();
  ASSERT_TRUE(times) << "a status poll waited for the commit";
  EXPECT_LT(times->slowest, kPollBound) << times->polls << " polls";
  EXPECT_TRUE(still_committing) << "the commit was held open during the polls";
  ASSERT_TRUE(queued_view);
  EXPECT_EQ(queued_view->record.state, JobState::kCancelled);
  EXPECT_FALSE(finished_view) << "a deleted job is 404 at once";

  EXPECT_EQ(submitting.get().kind, SubmitOutcome::Kind::kAccepted);
  EXPECT_EQ(deleting.get(), DeleteOutcome::kDeleted);
  EXPECT_EQ(cancelling.get(), DeleteOutcome::kCancelled);
  s->cancel_or_delete(running, 3000ms);
}

TEST(StatusPath, PollsDoNotWaitForAResultDeletion) {
  TempDir dir;
  Service s(dir.path());
  const std::string finished = submit_ok(*s, tiny_scene(8, 8, 1));
  ASSERT_EQ(wait_for_state(*s, finished, JobState::kSucceeded)->record.state, JobState::kSucceeded);
  const std::string other = submit_ok(*s, tiny_scene(8, 8, 1));
  ASSERT_EQ(wait_for_state(*s, other, JobState::kSucceeded)->record.state, JobState::kSucceeded);

  s.delete_gate.close();
  auto deleting =
      std::async(std::launch::async, [&] { return s->cancel_or_delete(finished, 3000ms); });
  ASSERT_TRUE(s.delete_gate.wait_arrived(1)) << "the delete reached the file deletion";

  const auto times = poll_on_the_side(*s, {other, finished}, 200, 5s, s.delete_gate);
  const bool still_deleting = deleting.wait_for(0ms) == std::future_status::timeout;
  s.delete_gate.open();
  ASSERT_TRUE(times) << "a status poll waited for the file deletion";
  EXPECT_LT(times->slowest, kPollBound);
  EXPECT_TRUE(still_deleting);
  EXPECT_EQ(deleting.get(), DeleteOutcome::kDeleted);
  EXPECT_FALSE(s->open_result(finished, "png", std::nullopt));
  EXPECT_TRUE(s->open_result(other, "png", std::nullopt));
}

}  // namespace
}  // namespace penumbra::test
