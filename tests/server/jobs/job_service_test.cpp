// The job service in this process against a temporary SQLite file: status transitions, what a
// restart recovers, idempotency, deletion and expiry, queue order and cancellation.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/server/jobs/service_fixture.h"

namespace penumbra::test {
namespace {

using server::DeleteOutcome;
using server::JobRecord;
using server::JobState;
using server::SubmitOutcome;
using namespace std::chrono_literals;

std::optional<JobRecord> stored(server::JobStore& store, const std::string& id) {
  for (JobRecord& r : store.load().records)
    if (r.id == id) return r;
  return std::nullopt;
}

TEST(JobService, AJobGoesFromQueuedThroughRunningToSucceededOnDisk) {
  TempDir dir;
  Service s(dir.path());
  const SubmitOutcome o = s->submit(tiny_scene(8, 8, 2).dump(), "");
  ASSERT_EQ(o.kind, SubmitOutcome::Kind::kAccepted);
  EXPECT_EQ(o.record.state, JobState::kQueued);
  // Acknowledged means committed: the record is in the file before submit returns.
  ASSERT_TRUE(stored(s.sqlite(), o.record.id));
  const auto done = wait_for_state(*s, o.record.id, JobState::kSucceeded);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->record.state, JobState::kSucceeded);
  EXPECT_EQ(done->record.attempts, 1);
  EXPECT_GT(done->record.started_at, 0);
  EXPECT_GE(done->record.finished_at, done->record.started_at);
  EXPECT_NE(done->record.stats_json.find("\"camera_samples\":128"), std::string::npos)
      << done->record.stats_json;
  const auto png = s->open_result(o.record.id, "png", std::nullopt);
  ASSERT_TRUE(png);
  EXPECT_GT(png->size, 0u);
  s.stop();  // every decided change is written
  const auto on_disk = stored(s.sqlite(), o.record.id);
  ASSERT_TRUE(on_disk);
  EXPECT_EQ(on_disk->state, JobState::kSucceeded);
  EXPECT_EQ(on_disk->stats_json, done->record.stats_json);
}

TEST(JobService, AnInvalidSceneIsRefusedAndNothingIsStored) {
  TempDir dir;
  Service s(dir.path());
  Json scene = tiny_scene(8, 8, 1);
  scene["render"]["spp"] = 0;
  const SubmitOutcome o = s->submit(scene.dump(), "");
  EXPECT_EQ(o.kind, SubmitOutcome::Kind::kInvalid);
  ASSERT_FALSE(o.errors.empty());
  EXPECT_EQ(o.errors.front().pointer, "/render/spp");
  EXPECT_EQ(s->submit("{\"version\": 1,", "").kind, SubmitOutcome::Kind::kSyntax);
  EXPECT_TRUE(s.sqlite().load().records.empty());
}

// A crash (kill -9) leaves jobs stored as running and queued; written here straight into the
// file, as the crashed server would have left it.
TEST(JobService, ARestartRunsInterruptedAndQueuedJobsInSubmissionOrder) {
  TempDir dir;
  {
    server::SqliteJobStore store(dir.path() + "/jobs.db");
    std::vector<server::JobChange> crashed;
    auto job = [&](int seq, JobState state, int attempts) {
      JobRecord r;
      r.id = std::string(22, '0') + std::to_string(10 + seq);
      r.seq = seq;
      r.state = state;
      r.attempts = attempts;
      r.created_at = 1.0 + seq;
      r.started_at = state == JobState::kRunning ? 2.0 : 0;
      crashed.push_back(server::InsertJob{r, tiny_scene(8, 8, 1).dump()});
      return r.id;
    };
    job(1, JobState::kRunning, 1);  // interrupted once: runs again
    job(2, JobState::kQueued, 0);
    job(3, JobState::kRunning, 3);  // interrupted three times: fails instead of crash-looping
    job(4, JobState::kQueued, 0);
    store.apply(crashed);
  }
  Service s(dir.path());
  const std::string first = std::string(22, '0') + "11", second = std::string(22, '0') + "12";
  const std::string looping = std::string(22, '0') + "13", last = std::string(22, '0') + "14";
  const auto a = wait_for_state(*s, first, JobState::kSucceeded);
  const auto b = wait_for_state(*s, second, JobState::kSucceeded);
  const auto d = wait_for_state(*s, last, JobState::kSucceeded);
  const auto c = wait_until(*s, looping, [](JobState st) { return server::is_finished(st); });
  ASSERT_TRUE(a && b && c && d);
  EXPECT_EQ(a->record.state, JobState::kSucceeded);
  EXPECT_EQ(a->record.attempts, 2) << "counted once before the crash, once after";
  EXPECT_EQ(b->record.attempts, 1);
  EXPECT_EQ(c->record.state, JobState::kFailed);
  EXPECT_NE(c->record.error_json.find("interrupted 3 times"), std::string::npos);
  EXPECT_EQ(d->record.state, JobState::kSucceeded);
  // One worker: each started after the one before it finished, in seq order.
  EXPECT_GE(b->record.started_at, a->record.finished_at);
  EXPECT_GE(d->record.started_at, b->record.finished_at);
}

TEST(JobService, IdempotencyKeysReplayRefuseSurviveARestartAndAreFreedByDelete) {
  TempDir dir;
  const std::string body = tiny_scene(8, 8, 1).dump();
  std::string id;
  {
    Service s(dir.path());
    const SubmitOutcome first = s->submit(body, "order-42");
    ASSERT_EQ(first.kind, SubmitOutcome::Kind::kAccepted);
    id = first.record.id;
    const SubmitOutcome again = s->submit(body, "order-42");
    EXPECT_EQ(again.kind, SubmitOutcome::Kind::kReplayed);
    EXPECT_EQ(again.record.id, id);
    const SubmitOutcome other = s->submit(tiny_scene(8, 8, 2).dump(), "order-42");
    EXPECT_EQ(other.kind, SubmitOutcome::Kind::kKeyReused);
    EXPECT_EQ(other.record.id, id);
    EXPECT_NE(s->submit(body, "").record.id, id) << "no key, a new job";
    wait_for_state(*s, id, JobState::kSucceeded);
  }
  Service s(dir.path());
  const SubmitOutcome after_restart = s->submit(body, "order-42");
  EXPECT_EQ(after_restart.kind, SubmitOutcome::Kind::kReplayed);
  EXPECT_EQ(after_restart.record.id, id);
  EXPECT_EQ(s->cancel_or_delete(id, 0ms), DeleteOutcome::kDeleted);
  const SubmitOutcome fresh = s->submit(body, "order-42");
  EXPECT_EQ(fresh.kind, SubmitOutcome::Kind::kAccepted);
  EXPECT_NE(fresh.record.id, id);
}

TEST(JobService, DeleteRemovesTheResultAndLeavesATombstoneThatSurvivesARestart) {
  TempDir dir;
  std::string id;
  {
    Service s(dir.path());
    id = submit_ok(*s, tiny_scene(8, 8, 1));
    ASSERT_EQ(wait_for_state(*s, id, JobState::kSucceeded)->record.state, JobState::kSucceeded);
    ASSERT_TRUE(std::filesystem::exists(s.files().path(id, "png")));
    EXPECT_EQ(s->cancel_or_delete(id, 0ms), DeleteOutcome::kDeleted);
    EXPECT_FALSE(s->view(id));
    EXPECT_FALSE(std::filesystem::exists(s.files().path(id, "png")));
    EXPECT_FALSE(std::filesystem::exists(s.files().path(id, "exr")));
    EXPECT_EQ(s->cancel_or_delete(id, 0ms), DeleteOutcome::kDeleted) << "DELETE is idempotent";
    const auto tombstone = stored(s.sqlite(), id);  // durable before DELETE answered
    ASSERT_TRUE(tombstone);
    EXPECT_EQ(tombstone->state, JobState::kDeleted);
    EXPECT_FALSE(s.sqlite().scene(id)) << "the scene text is dropped";
  }
  Service s(dir.path());
  EXPECT_FALSE(s->view(id));
  EXPECT_EQ(s->cancel_or_delete(id, 0ms), DeleteOutcome::kDeleted);
  EXPECT_EQ(s->cancel_or_delete(std::string(24, 'a'), 0ms), DeleteOutcome::kNotFound);
}

TEST(JobService, FinishedJobsExpireFromMemoryTheStoreAndTheDisk) {
  TempDir dir;
  server::ServerConfig config = service_config(dir.path());
  config.retention_seconds = 0.3;
  Service s(dir.path(), config);
  const std::string id = submit_ok(*s, tiny_scene(8, 8, 1));
  // It renders, then goes 0.3 s after it finished (polling for "succeeded" could miss it).
  const auto gone = wait_until(
      *s, id, [](JobState) { return false; }, 10s);
  EXPECT_FALSE(gone) << "expired after the retention";
  s.stop();
  EXPECT_FALSE(stored(s.sqlite(), id)) << "and erased from the store";
  EXPECT_FALSE(std::filesystem::exists(s.files().path(id, "png")));
}

TEST(JobService, TheQueueIsFifoAndCancellingAQueuedJobTakesItOut) {
  TempDir dir;
  Service s(dir.path());
  const std::string running = submit_ok(*s, long_scene());
  ASSERT_EQ(wait_for_state(*s, running, JobState::kRunning)->record.state, JobState::kRunning);
  const std::string a = submit_ok(*s, tiny_scene(8, 8, 1));
  const std::string b = submit_ok(*s, tiny_scene(8, 8, 1));
  const std::string c = submit_ok(*s, tiny_scene(8, 8, 1));
  EXPECT_EQ(s->view(a)->queue_position, 0u);
  EXPECT_EQ(s->view(b)->queue_position, 1u);
  EXPECT_EQ(s->view(c)->queue_position, 2u);
  EXPECT_EQ(s->cancel_or_delete(b, 0ms), DeleteOutcome::kCancelled);
  EXPECT_EQ(s->view(b)->record.state, JobState::kCancelled);
  EXPECT_FALSE(s->view(b)->queue_position);
  EXPECT_EQ(s->view(c)->queue_position, 1u) << "b left the queue";
  // Newest first in listings, queued ones with their place.
  const auto listed = s->list(std::nullopt, 0, 10);
  ASSERT_EQ(listed.size(), 4u);
  EXPECT_EQ(listed[0].record.id, c);
  EXPECT_EQ(listed[3].record.id, running);
  EXPECT_EQ(s->list(JobState::kQueued, 0, 10).size(), 2u);

  EXPECT_EQ(s->cancel_or_delete(running, 5000ms), DeleteOutcome::kCancelled);
  EXPECT_EQ(s->view(running)->record.state, JobState::kCancelled);
  const auto done_a = wait_for_state(*s, a, JobState::kSucceeded);
  const auto done_c = wait_for_state(*s, c, JobState::kSucceeded);
  ASSERT_TRUE(done_a && done_c);
  EXPECT_GE(done_c->record.started_at, done_a->record.finished_at);
  EXPECT_EQ(s->view(b)->record.state, JobState::kCancelled) << "a cancelled job never runs";
}

TEST(JobService, ShutdownPutsTheRunningRenderBackWithoutCountingTheAttempt) {
  TempDir dir;
  std::string id;
  {
    Service s(dir.path());
    id = submit_ok(*s, long_scene());
    ASSERT_EQ(wait_for_state(*s, id, JobState::kRunning)->record.state, JobState::kRunning);
    s.stop();
    const auto on_disk = stored(s.sqlite(), id);
    ASSERT_TRUE(on_disk);
    EXPECT_EQ(on_disk->state, JobState::kQueued);
    EXPECT_EQ(on_disk->attempts, 0);
  }
  Service s(dir.path());
  ASSERT_EQ(wait_for_state(*s, id, JobState::kRunning)->record.attempts, 1);
  EXPECT_EQ(s->cancel_or_delete(id, 5000ms), DeleteOutcome::kCancelled);
}

}  // namespace
}  // namespace penumbra::test
