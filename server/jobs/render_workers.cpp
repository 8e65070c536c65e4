#include "server/jobs/render_workers.h"

#include <filesystem>

#include "server/storage/asset_store.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "api/version.h"
#include "renderer/io/image_io.h"
#include "server/jobs/unix_time.h"
#include "server/storage/result_files.h"

namespace penumbra::server {
namespace {

// A job that has started this many times without finishing keeps killing the server (or the
// machine): it fails instead of running forever after every restart.
constexpr int kMaxAttempts = 3;
// At shutdown, a render that will be done within this many seconds is finished, not requeued.
constexpr double kFinishAtShutdownSeconds = 5.0;

std::string error_json(const std::string& detail) {
  return nlohmann::ordered_json{{"detail", detail}}.dump();
}

// A running (or, when `from_queued`, a queued) job ends in `state`.
std::function<bool(JobEntry&)> settle(JobState state, double now, std::string stats,
                                      std::string error, bool from_queued = false) {
  return [=](JobEntry& e) {
    const bool live = e.record.state == JobState::kRunning ||
                      (from_queued && e.record.state == JobState::kQueued);
    if (!live) return false;
    e.record.state = state;
    e.record.finished_at = now;
    e.record.stats_json = stats;
    e.record.error_json = error;
    e.runtime = nullptr;
    return true;
  };
}

}  // namespace

RenderWorkers::RenderWorkers(const ServerConfig& config, JobQueue& queue, JobTable& table,
                             StoreWriter& writer, JobStore& store, ResultStore& results,
                             Metrics& metrics)
    : config_(config),
      queue_(queue),
      table_(table),
      writer_(writer),
      store_(store),
      results_(results),
      metrics_(metrics) {}

RenderWorkers::~RenderWorkers() { join(); }

void RenderWorkers::start(int count) {
  {
    std::lock_guard lock(mutex_);
    live_ = count;
  }
  for (int i = 0; i < count; ++i) threads_.emplace_back([this] { loop(); });
}

void RenderWorkers::begin_shutdown() {
  // Set before the runtimes are read: a claim after this sees it and leaves its job queued
  // (claims and runtimes() both hold the table's lock, so no render slips between).
  stopping_ = true;
  for (const auto& runtime : table_.runtimes()) {
    const RenderProgress p = runtime->progress();
    const bool nearly_done = p.fraction > 0 && p.eta_seconds < kFinishAtShutdownSeconds;
    if (!nearly_done) runtime->request_stop(JobRuntime::StopReason::kShutdown);
  }
}

bool RenderWorkers::wait_stopped(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return done_cv_.wait_until(lock, deadline, [&] { return live_ == 0; });
}

void RenderWorkers::join() {
  for (auto& t : threads_)
    if (t.joinable()) t.join();
}

void RenderWorkers::loop() {
  while (auto id = queue_.pop()) {
    try {
      run_job(*id);
    } catch (const std::exception& e) {
      // A bug or a full disk: the job fails with a generic message; the details go to the log.
      std::fprintf(stderr, "penumbra serve: job %s: internal error: %s\n", id->c_str(), e.what());
      table_.modify(*id, settle(JobState::kFailed, unix_now(), "",
                                error_json("internal error while rendering; see the server log"),
                                /*from_queued=*/true));
    }
  }
  {
    std::lock_guard lock(mutex_);
    --live_;
  }
  done_cv_.notify_all();
}

void RenderWorkers::run_job(const std::string& id) {
  auto runtime = std::make_shared<JobRuntime>();
  const double started = unix_now();
  const auto started_steady = std::chrono::steady_clock::now();
  int exhausted_attempts = 0;
  std::optional<int> resume_frame;  // an animation: the first frame not yet finished
  const auto ticket = table_.modify(id, [&](JobEntry& e) {
    // Cancelled meanwhile, or shutdown began after the pop: it stays queued for the restart.
    if (e.record.state != JobState::kQueued || stopping_) return false;
    if (e.record.attempts >= kMaxAttempts) {
      exhausted_attempts = e.record.attempts;
      return settle(JobState::kFailed, started, "",
                    error_json("the render was interrupted " + std::to_string(e.record.attempts) +
                               " times (server crash or kill); not retried again"),
                    /*from_queued=*/true)(e);
    }
    e.record.state = JobState::kRunning;
    e.record.started_at = started;
    if (e.record.frame_count() > 0) resume_frame = e.record.frame_first + e.record.frames_done;
    ++e.record.attempts;
    e.runtime = runtime;
    return true;
  });
  if (!ticket || exhausted_attempts > 0) return;
  // The attempt is on disk before a render that might take the process down starts:
  // kMaxAttempts counts on it.
  writer_.wait_durable(*ticket);
  const auto scene = store_.scene(id);
  if (!scene) {
    table_.modify(id, settle(JobState::kFailed, unix_now(), "",
                             error_json("the job's scene is missing from the store")));
    return;
  }
  RenderJobOptions options;
  options.limits = config_.scene_limits();
  options.threads = config_.threads_per_job();
  options.max_render_seconds = config_.max_render_seconds;
  options.started = started_steady;
  options.assets.root = job_asset_folder(config_.data_dir, id);
  options.assets.max_file_bytes = int64_t(config_.max_asset_bytes);
  if (std::error_code ec; !std::filesystem::is_directory(options.assets.root, ec))
    options.assets.root.clear();  // a job that names no files
  options.resume_frame = resume_frame;
  options.on_frame = [this, &id](int frame, const RenderOutcome& frame_outcome) {
    // Files first, then frames_done, durable before the next frame starts: a kill -9 from here
    // on resumes after this frame, and a frame counted done always has its files.
    write_results(results_, id, frame_outcome.image, frame_outcome.layers,
                  result_metadata(id, frame_outcome), frame);
    const auto done = table_.modify(id, [frame](JobEntry& e) {
      if (e.record.state != JobState::kRunning) return false;
      e.record.frames_done = std::max(e.record.frames_done, frame - e.record.frame_first + 1);
      return true;
    });
    if (done) writer_.wait_durable(*done);
  };
  const RenderOutcome outcome = run_render_job(*scene, options, *runtime);
  if (outcome.kind == RenderOutcome::Kind::kStopped &&
      runtime->stop_reason() == JobRuntime::StopReason::kShutdown) {
    table_.modify(id, [](JobEntry& e) {  // runs again after the restart; the attempt does not count
      if (e.record.state != JobState::kRunning) return false;
      e.record.state = JobState::kQueued;
      e.record.started_at = 0;
      e.record.attempts = std::max(e.record.attempts - 1, 0);
      e.runtime = nullptr;
      return true;
    });
    return;
  }
  finish_job(id, outcome, options.threads);
}

void RenderWorkers::finish_job(const std::string& id, const RenderOutcome& outcome, int threads) {
  const double now = unix_now();
  switch (outcome.kind) {
    case RenderOutcome::Kind::kSucceeded: {
      const ImageMetadata meta = result_metadata(id, outcome);
      // Files first, then the record: a crash in between reruns the job, never serves a
      // missing file.
      // An animation's frames were each stored as they finished (options.on_frame).
      if (!outcome.animation) write_results(results_, id, outcome.image, outcome.layers, meta);
      table_.modify(id, settle(JobState::kSucceeded, now, render_stats_json(outcome, threads), ""));
      metrics_.observe_render("succeeded", outcome.stats.seconds, outcome.stats.rays);
      if (outcome.stats.stopped_by_time_limit) metrics_.count_stopped_early("time_limit");
      const double total = outcome.stats.seconds + outcome.build_seconds;
      const double average = average_job_seconds_.load();
      average_job_seconds_ = average > 0 ? 0.8 * average + 0.2 * total : total;
      break;
    }
    case RenderOutcome::Kind::kStopped:
      table_.modify(id, settle(JobState::kCancelled, now, render_stats_json(outcome, threads), ""));
      metrics_.observe_render("cancelled", outcome.stats.seconds, outcome.stats.rays);
      break;
    case RenderOutcome::Kind::kFailed:
      table_.modify(id, settle(JobState::kFailed, now, "", error_json(outcome.error)));
      metrics_.observe_render("failed", 0, 0);
      break;
  }
}

}  // namespace penumbra::server
