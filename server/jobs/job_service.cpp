#include "server/jobs/job_service.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <limits>
#include <random>

#include "server/jobs/job_options.h"
#include "api/diagnostics.h"
#include "api/job_submission.h"
#include "server/jobs/retry_estimate.h"
#include "server/jobs/submission_check.h"
#include "server/jobs/unix_time.h"
#include "server/storage/disk_space.h"
#include "server/storage/result_files.h"

namespace penumbra::server {

bool JobService::job_is_live(const std::string& id) const {
  const auto entry = table_.find(id);
  return entry &&
         (entry->record.state == JobState::kQueued || entry->record.state == JobState::kRunning);
}

JobService::JobService(const ServerConfig& config, JobStore& store, ResultStore& results,
                       Metrics& metrics, AssetStore* assets)
    : config_(config),
      store_(store),
      results_(results),
      metrics_(metrics),
      assets_(assets),
      writer_(store),
      table_(writer_),
      queue_(std::size_t(config.max_queue)),
      workers_(config_, queue_, table_, writer_, store, results, metrics),
      webhooks_(WebhookSettings{config_.webhook_hosts(), config_.webhook_timeout_seconds,
                                config_.webhook_retry_seconds, 2},
                metrics) {
  table_.set_observer([this](const JobEntry& e) { observe(e); });
}

void JobService::observe(const JobEntry& e) {
  const JobRecord& r = e.record;
  std::optional<std::size_t> position;
  if (r.state == JobState::kQueued) position = queue_.position(r.id);  // queue_: a leaf lock
  events_.record_change(r, position);
  // The job has just ended (no attempt yet): its webhook is due now. Later attempts are
  // scheduled by the sender itself.
  if (WebhookSender::pending(r) && r.notify.attempts == 0) webhooks_.schedule(r.id, 0);
}

JobService::~JobService() {
  begin_shutdown();
  stop(std::chrono::steady_clock::now() + std::chrono::hours(1));
}

void JobService::start() {
  StoredJobs stored = store_.load();
  last_seq_ = stored.last_seq;
  // A crash between a tombstone's commit and the removal of its files leaves the files.
  for (const JobRecord& r : stored.records)
    if (r.state == JobState::kDeleted) results_.remove(r.id);
  for (const std::string& id : table_.restore(std::move(stored.records))) {
    const auto e = table_.find(id);
    queue_.push(id, e ? e->record.priority : 0, e ? e->record.seq : 0, /*force=*/true);
  }
  expire_now();
  // Webhooks of finished jobs not yet delivered (the server stopped or was killed before a 2xx):
  // at least once means they are sent again.
  for (const JobState state : {JobState::kSucceeded, JobState::kFailed, JobState::kCancelled})
    for (const JobEntry& e : table_.list(state, 0, std::numeric_limits<int>::max()))
      if (WebhookSender::pending(e.record)) webhooks_.schedule(e.record.id, e.record.notify.next_attempt_at);
  webhooks_.start(WebhookSender::Hooks{
      [this](const std::string& id) -> std::optional<JobRecord> {
        auto e = table_.find(id);
        if (!e) return std::nullopt;
        return std::move(e->record);
      },
      [this](const JobRecord& r) {
        return webhook_body_ ? webhook_body_(r)
                             : nlohmann::json{{"id", r.id}, {"state", to_string(r.state)}}.dump();
      },
      [this](const std::string& id, const JobRecord::Notify& status) {
        table_.modify(id, [&](JobEntry& e) {
          if (e.record.notify.url.empty() || e.record.state == JobState::kDeleted) return false;
          e.record.notify = status;
          return true;
        });
      }});
  if (assets_) {
    // Folders of jobs that finished, were deleted or expired while the server was down go now.
    assets_->set_job_liveness([this](const std::string& id) { return job_is_live(id); });
    assets_->sweep_job_folders();
  }
  workers_.start(config_.workers);
  reaper_ = std::thread([this] { reaper_loop(); });
}

double JobService::retry_after_for_queue() const {
  std::vector<RunningJobEstimate> running;
  for (const auto& runtime : table_.runtimes()) {
    const RenderProgress p = runtime->progress();
    running.push_back({p.fraction, p.eta_seconds});
  }
  return queue_retry_after_seconds(running, workers_.average_job_seconds(), config_.workers);
}

std::uint64_t JobService::reserved_bytes() const {
  std::uint64_t total = 0;
  const int limit = config_.max_queue + config_.workers + 1;
  for (const JobState state : {JobState::kQueued, JobState::kRunning})
    for (const JobEntry& e : table_.list(state, 0, limit))
      // An animation still to write its frames from frames_done on (written ones are on disk).
      total += worst_case_result_bytes(e.record.width, e.record.height) *
               std::uint64_t(std::max(1, e.record.frame_count() - e.record.frames_done));
  return total;
}

bool JobService::storage_ok() const {
  const auto available = available_bytes(config_.data_dir);
  return !available || *available >= config_.min_free_bytes;
}

SubmitOutcome JobService::submit(std::string_view body, const std::string& idempotency_key) {
  SubmitOutcome out;
  auto refuse_shutting_down = [&] {
    out.kind = SubmitOutcome::Kind::kNotAccepting;
    out.retry_after_seconds = 5;
    return out;
  };
  if (!accepting_) return refuse_shutting_down();
  PreparedSubmission prepared = prepare_submission(config_, assets_, body, idempotency_key);
  if (prepared.refusal) return std::move(*prepared.refusal);
  out.warnings = std::move(prepared.warnings);
  const std::string& scene_json = prepared.scene_json;
  JobRecord r = std::move(prepared.record);
  std::lock_guard submit_lock(submit_mutex_);
  if (!idempotency_key.empty()) {
    if (auto existing = table_.find_by_key(idempotency_key)) {
      // Read from the store: the table keeps no scenes. A submission may wait on a commit here.
      const auto stored_scene = store_.scene(existing->id);
      const bool same = stored_scene == scene_json && existing->priority == r.priority &&
                        existing->notify.url == r.notify.url &&
                        existing->notify.secret == r.notify.secret;
      out.record = std::move(*existing);
      out.kind = same ? SubmitOutcome::Kind::kReplayed : SubmitOutcome::Kind::kKeyReused;
      return out;
    }
  }
  if (!accepting_) return refuse_shutting_down();
  if (queue_.full()) {
    out.kind = SubmitOutcome::Kind::kQueueFull;
    out.retry_after_seconds = retry_after_for_queue();
    return out;
  }
  // Room for this job's images, the scene, the images promised to jobs already accepted, and the
  // margin; checked before anything is written (under submit_mutex_, so two submissions cannot
  // both take the last room).
  if (const auto available = available_bytes(config_.data_dir)) {
    const std::uint64_t needed =
        prepared.worst_case_bytes + body.size() + reserved_bytes() + config_.min_free_bytes;
    if (*available < needed) {
      out.kind = SubmitOutcome::Kind::kNoSpace;
      out.bytes_needed = needed;
      out.bytes_available = *available;
      return out;
    }
  }
  r.seq = last_seq_ + 1;
  // Committed (fsync'd) before anyone hears 202. Nobody knows the id yet, so no other change
  // of this job can be queued before its insert.
  try {
    writer_.wait_durable(writer_.enqueue(InsertJob{r, scene_json}));
  } catch (const StoreError& e) {
    // Nothing was accepted: the job is in neither the table nor the queue. A full disk is the
    // usual cause (507); anything else is a storage failure worth retrying (503), never a 500.
    std::fprintf(stderr, "penumbra serve: storing a new job failed: %s\n", e.what());
    const auto available = available_bytes(config_.data_dir);
    out.kind = available && *available < config_.min_free_bytes
                   ? SubmitOutcome::Kind::kNoSpace
                   : SubmitOutcome::Kind::kStoreFailed;
    out.bytes_available = available.value_or(0);
    out.bytes_needed = prepared.worst_case_bytes + body.size() + config_.min_free_bytes;
    out.retry_after_seconds = 5;
    return out;
  }
  last_seq_ = r.seq;
  table_.add(r);
  // Now the table says the job is queued: the folder stays.
  if (prepared.folder) prepared.folder->commit();
  queue_.push(r.id, r.priority, r.seq, /*force=*/true);  // capacity checked under submit_mutex_
  metrics_.count_submitted();
  out.record = std::move(r);
  out.kind = SubmitOutcome::Kind::kAccepted;
  return out;
}

nlohmann::json JobService::workers() const {
  nlohmann::json all = nlohmann::json::array();
  nlohmann::json running = nlohmann::json::array();
  for (const JobEntry& e : table_.list(JobState::kRunning, 0, config_.workers + 1))
    running.push_back({{"kind", "job"}, {"job", e.record.id}});
  all.push_back({{"id", "local"},
                 {"role", "all"},
                 {"render_threads", config_.threads_per_job()},
                 {"slots", config_.workers},
                 {"current_tasks", running}});
  return all;
}

JobView JobService::make_view(JobEntry entry) const {
  JobView v;
  v.record = std::move(entry.record);
  if (v.record.state == JobState::kQueued) v.queue_position = queue_.position(v.record.id);
  if (v.record.state == JobState::kRunning && entry.runtime) v.progress = entry.runtime->progress();
  v.current_frame = in_order_current_frame(v.record);
  return v;
}

std::optional<JobView> JobService::view(const std::string& id) const {
  auto entry = table_.find(id);
  if (!entry || entry->record.state == JobState::kDeleted) return std::nullopt;
  const bool stop_requested =
      entry->runtime && entry->runtime->stop_reason() != JobRuntime::StopReason::kNone;
  JobView v = make_view(std::move(*entry));
  v.stop_requested = stop_requested;
  return v;
}

std::vector<JobView> JobService::list_queued(std::optional<RunKey> after, int limit) const {
  std::vector<JobEntry> queued =
      table_.list(JobState::kQueued, 0, std::numeric_limits<int>::max());
  const auto runs_before = [](int p1, int64_t s1, int p2, int64_t s2) {
    return p1 > p2 || (p1 == p2 && s1 < s2);
  };
  std::sort(queued.begin(), queued.end(), [&](const JobEntry& a, const JobEntry& b) {
    return runs_before(a.record.priority, a.record.seq, b.record.priority, b.record.seq);
  });
  std::vector<JobView> out;
  for (JobEntry& e : queued) {
    if (int(out.size()) >= limit) break;
    if (after && !runs_before(after->priority, after->seq, e.record.priority, e.record.seq))
      continue;
    out.push_back(make_view(std::move(e)));
  }
  return out;
}

std::vector<JobView> JobService::list(std::optional<JobState> state, int64_t before_seq,
                                      int limit) const {
  std::vector<JobView> out;
  for (JobEntry& e : table_.list(state, before_seq, limit)) out.push_back(make_view(std::move(e)));
  return out;
}

DeleteOutcome JobService::cancel_or_delete(const std::string& id, std::chrono::milliseconds wait) {
  enum class Found { kNothing, kTombstone, kFinished, kQueued, kRunning } found = Found::kNothing;
  const double now = unix_now();
  const auto ticket = table_.modify(id, [&](JobEntry& e) {
    JobRecord& r = e.record;
    if (r.state == JobState::kDeleted) {
      found = Found::kTombstone;  // deleted before: DELETE is idempotent
      return false;
    }
    if (is_finished(r.state)) {
      // The record stays as a tombstone so a repeated DELETE still answers 204; the key is freed.
      found = Found::kFinished;
      r.state = JobState::kDeleted;
      r.finished_at = now;
      r.idempotency_key.clear();
      r.stats_json.clear();
      r.error_json.clear();
      r.warnings_json.clear();
      r.notify = {};  // a delivery not yet made is dropped with the job
      return true;
    }
    if (r.state == JobState::kQueued) {
      // A worker that popped it meanwhile sees the state and skips it.
      found = Found::kQueued;
      r.state = JobState::kCancelled;
      r.finished_at = now;
      return true;
    }
    found = Found::kRunning;
    e.runtime->request_stop(JobRuntime::StopReason::kUserCancel);
    return false;
  });
  switch (found) {
    case Found::kNothing:
      return DeleteOutcome::kNotFound;
    case Found::kTombstone:
      return DeleteOutcome::kDeleted;
    case Found::kFinished:
      results_.remove(id);  // no lock held: polls of other jobs go on meanwhile
      if (assets_) assets_->remove_job_folder(id);
      writer_.wait_durable(*ticket);
      return DeleteOutcome::kDeleted;
    case Found::kQueued:
      queue_.remove(id);
      if (assets_) assets_->remove_job_folder(id);
      metrics_.observe_render("cancelled", 0, 0);
      writer_.wait_durable(*ticket);
      return DeleteOutcome::kCancelled;
    case Found::kRunning:
      break;
  }
  const auto after = table_.wait(
      id, std::chrono::steady_clock::now() + wait,
      [](const JobRecord& r) { return r.state != JobState::kRunning; }, [] { return false; });
  return !after || after->state != JobState::kRunning ? DeleteOutcome::kCancelled
                                                      : DeleteOutcome::kCancelling;
}

std::optional<StoredResult> JobService::open_result(const std::string& id,
                                                    const std::string& format,
                                                    std::optional<int> frame) const {
  const auto entry = table_.find(id);
  if (!entry || entry->record.state == JobState::kDeleted) return std::nullopt;
  const JobRecord& r = entry->record;
  if (r.frame_count() == 0) return frame ? std::nullopt : results_.open(id, format);
  // An animation: only frames counted done (their files were stored before the count).
  const int f = frame.value_or(r.frame_first);
  if (f < r.frame_first || f >= r.frame_first + r.frames_done) return std::nullopt;
  return results_.open(id, frame_result_key(f, format));
}

std::shared_ptr<const Image> JobService::preview(const std::string& id) const {
  const auto entry = table_.find(id);
  return entry && entry->runtime ? entry->runtime->preview() : nullptr;
}

std::optional<JobRecord> JobService::wait_finished(
    const std::string& id, std::chrono::steady_clock::time_point deadline) const {
  return table_.wait(
      id, deadline,
      [](const JobRecord& r) { return is_finished(r.state) || r.state == JobState::kDeleted; },
      [this] { return stopping_.load(); });
}

void JobService::expire_now() {
  const std::vector<std::string> ids = table_.take_expired(unix_now() - config_.retention_seconds);
  if (ids.empty()) return;
  // Records first, then files (as before the table existed): a crash in between leaves files
  // nobody serves, never a record whose image is gone.
  writer_.flush();
  for (const std::string& id : ids) {
    results_.remove(id);
    events_.forget(id);
    if (assets_) assets_->remove_job_folder(id);
  }
}

void JobService::reaper_loop() {
  const auto period =
      std::chrono::duration<double>(std::clamp(config_.retention_seconds / 4, 0.05, 60.0));
  std::unique_lock lock(reaper_mutex_);
  while (!stopping_) {
    reaper_cv_.wait_for(lock, period, [&] { return stopping_.load(); });
    if (stopping_) break;
    try {
      expire_now();
      if (assets_) assets_->sweep_job_folders();  // jobs finished since: their files are free
    } catch (const std::exception& e) {
      std::fprintf(stderr, "penumbra serve: expiry failed: %s\n", e.what());
    }
  }
}

void JobService::begin_shutdown() {
  if (!accepting_.exchange(false) && stopping_) return;
  {
    std::lock_guard submit_lock(submit_mutex_);  // no submission is half-way through
  }
  stopping_ = true;
  workers_.begin_shutdown();
  queue_.close();
  table_.wake_all();
  events_.wake_all();  // event streams end
  { std::lock_guard rl(reaper_mutex_); }
  reaper_cv_.notify_all();
}

bool JobService::stop(std::chrono::steady_clock::time_point deadline) {
  if (!workers_.wait_stopped(deadline)) {
    writer_.flush();  // what has been decided is written; the stuck render's job runs again
    return false;     // a thread still runs (e.g. a scene build): the caller exits hard
  }
  workers_.join();
  if (reaper_.joinable()) reaper_.join();
  webhooks_.stop();  // an attempt under way ends within --webhook-timeout; pending ones stay stored
  writer_.flush();
  return true;
}

Metrics::Gauges JobService::gauges() const {
  Metrics::Gauges g;
  for (const auto& [state, n] : table_.count_by_state()) {
    if (state != JobState::kDeleted) g.jobs_by_state[to_string(state)] = n;
    if (state == JobState::kRunning) g.running = n;
  }
  g.queue_depth = int64_t(queue_.size());
  g.queue_capacity = int64_t(queue_.capacity());
  g.ready = accepting_;
  g.webhooks_pending = int64_t(webhooks_.backlog());
  g.event_streams = events_.open_streams();
  return g;
}

}  // namespace penumbra::server
