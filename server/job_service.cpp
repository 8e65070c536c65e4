#include "server/job_service.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <nlohmann/json.hpp>

#include "api/version.h"
#include "renderer/io/image_io.h"

namespace penumbra::server {
namespace {

// A job that has started this many times without finishing keeps killing the server (or the
// machine): it fails instead of running forever after every restart.
constexpr int kMaxAttempts = 3;
// At shutdown, a render that will be done within this many seconds is finished, not requeued.
constexpr double kFinishAtShutdownSeconds = 5.0;

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

nlohmann::json diagnostics_json(const std::vector<api::Diagnostic>& ds) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& d : ds) a.push_back({{"pointer", d.pointer}, {"detail", d.message}});
  return a;
}

std::string error_json(const std::string& detail) {
  return nlohmann::ordered_json{{"detail", detail}}.dump();
}

std::string stats_json(const RenderOutcome& o, int threads) {
  const RenderStats& s = o.stats;
  return nlohmann::ordered_json{{"seconds", s.seconds},
                        {"build_seconds", o.build_seconds},
                        {"rays", s.rays},
                        {"mrays_per_second", s.mrays_per_second()},
                        {"spp_mean", s.spp_mean},
                        {"spp_min", s.spp_min},
                        {"spp_max", s.spp_max},
                        {"camera_samples", s.camera_samples},
                        {"stopped_by_time_limit", s.stopped_by_time_limit},
                        {"threads", threads}}
      .dump();
}

}  // namespace

JobService::JobService(const ServerConfig& config, JobStore& store, ResultFiles& files,
                       Metrics& metrics)
    : config_(config), store_(store), files_(files), metrics_(metrics),
      queue_(std::size_t(config.max_queue)) {}

JobService::~JobService() {
  begin_shutdown();
  stop(std::chrono::steady_clock::now() + std::chrono::hours(1));
}

void JobService::start() {
  for (const JobRecord& r : store_.recover()) queue_.push(r.id, /*force=*/true);
  expire_now();
  live_workers_ = config_.workers;
  for (int i = 0; i < config_.workers; ++i) workers_.emplace_back([this] { worker_loop(); });
  reaper_ = std::thread([this] { reaper_loop(); });
}

std::string JobService::new_job_id() {
  static thread_local std::random_device rd;  // /dev/urandom: ids are unguessable
  static const char* kHex = "0123456789abcdef";
  std::string id;
  for (int i = 0; i < 6; ++i) {
    const uint32_t v = rd();
    for (int k = 0; k < 4; ++k) id += kHex[(v >> (k * 4)) & 15];
  }
  return id;
}

double JobService::retry_after_for_queue() const {
  std::lock_guard lock(mutex_);
  const double per_job = average_job_seconds_ > 0 ? average_job_seconds_ : 5.0;
  const double wait = per_job * double(queue_.size()) / std::max(1, config_.workers);
  return std::clamp(wait, 1.0, 3600.0);
}

SubmitOutcome JobService::submit(std::string_view body, const std::string& idempotency_key) {
  SubmitOutcome out;
  if (!accepting_) {
    out.kind = SubmitOutcome::Kind::kNotAccepting;
    out.retry_after_seconds = 5;
    return out;
  }
  api::LoadResult loaded = api::load_scene(body, config_.scene_limits());
  out.warnings = loaded.warnings;
  if (!loaded.ok()) {
    out.kind = loaded.kind == api::LoadErrorKind::kSyntax ? SubmitOutcome::Kind::kSyntax
                                                          : SubmitOutcome::Kind::kInvalid;
    out.errors = std::move(loaded.errors);
    return out;
  }
  const std::string scene_json(body);
  std::lock_guard submit_lock(submit_mutex_);
  if (!idempotency_key.empty()) {
    if (auto match = store_.find_by_idempotency_key(idempotency_key, scene_json)) {
      out.record = match->record;
      out.kind = match->same_scene ? SubmitOutcome::Kind::kReplayed : SubmitOutcome::Kind::kKeyReused;
      return out;
    }
  }
  if (!accepting_) {
    out.kind = SubmitOutcome::Kind::kNotAccepting;
    out.retry_after_seconds = 5;
    return out;
  }
  if (queue_.full()) {
    out.kind = SubmitOutcome::Kind::kQueueFull;
    out.retry_after_seconds = retry_after_for_queue();
    return out;
  }
  const RenderSettings& s = loaded.request->settings;
  JobRecord r;
  r.id = new_job_id();
  r.idempotency_key = idempotency_key;
  r.created_at = unix_now();
  r.width = s.width;
  r.height = s.height;
  r.spp = s.spp;
  r.samples_total = uint64_t(s.width) * uint64_t(s.height) * uint64_t(s.spp);
  if (!out.warnings.empty()) r.warnings_json = diagnostics_json(out.warnings).dump();
  // Committed (fsync'd) before anyone hears 202.
  out.record = store_.insert(r, scene_json).record;
  queue_.push(r.id, /*force=*/true);  // capacity was checked under submit_mutex_
  metrics_.count_submitted();
  out.kind = SubmitOutcome::Kind::kAccepted;
  return out;
}

std::optional<JobView> JobService::view(const std::string& id) {
  auto record = store_.get(id);
  if (!record || record->state == JobState::kDeleted) return std::nullopt;
  JobView v;
  v.record = std::move(*record);
  if (v.record.state == JobState::kQueued) {
    v.queue_position = queue_.position(id);
  } else if (v.record.state == JobState::kRunning) {
    std::lock_guard lock(mutex_);
    if (auto it = running_.find(id); it != running_.end()) {
      v.progress = it->second->progress();
      v.stop_requested = it->second->stop_reason() != JobRuntime::StopReason::kNone;
    }
  }
  return v;
}

std::vector<JobView> JobService::list(std::optional<JobState> state, int64_t before_seq, int limit) {
  std::vector<JobView> out;
  for (JobRecord& r : store_.list(state, before_seq, limit)) {
    JobView v;
    v.record = std::move(r);
    if (v.record.state == JobState::kQueued) v.queue_position = queue_.position(v.record.id);
    if (v.record.state == JobState::kRunning) {
      std::lock_guard lock(mutex_);
      if (auto it = running_.find(v.record.id); it != running_.end()) v.progress = it->second->progress();
    }
    out.push_back(std::move(v));
  }
  return out;
}

DeleteOutcome JobService::cancel_or_delete(const std::string& id, std::chrono::milliseconds wait) {
  std::unique_lock lock(mutex_);
  auto record = store_.get(id);
  if (!record) return DeleteOutcome::kNotFound;
  if (record->state == JobState::kDeleted) return DeleteOutcome::kDeleted;  // idempotent
  if (is_finished(record->state)) {
    files_.remove(id);
    store_.mark_deleted(id, unix_now());
    return DeleteOutcome::kDeleted;
  }
  if (queue_.remove(id) || !running_.count(id)) {
    // Queued, or popped by a worker that has not registered it yet: the worker reads the
    // state before it starts and skips a cancelled job.
    store_.mark_finished(id, JobState::kCancelled, unix_now(), "", "");
    metrics_.observe_render("cancelled", 0, 0);
    finished_cv_.notify_all();
    return DeleteOutcome::kCancelled;
  }
  running_.at(id)->request_stop(JobRuntime::StopReason::kUserCancel);
  const bool stopped = finished_cv_.wait_for(lock, wait, [&] { return !running_.count(id); });
  return stopped ? DeleteOutcome::kCancelled : DeleteOutcome::kCancelling;
}

std::shared_ptr<const Image> JobService::preview(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = running_.find(id);
  return it == running_.end() ? nullptr : it->second->preview();
}

std::optional<JobRecord> JobService::wait_finished(const std::string& id,
                                                   std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  for (;;) {
    auto record = store_.get(id);
    if (!record || is_finished(record->state) || record->state == JobState::kDeleted ||
        stopping_ || std::chrono::steady_clock::now() >= deadline)
      return record;
    // Woken by every finished job; the timeout bounds a missed wake-up.
    finished_cv_.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() +
                                                         std::chrono::milliseconds(500)));
  }
}

void JobService::worker_loop() {
  while (auto id = queue_.pop()) {
    auto runtime = std::make_shared<JobRuntime>();
    {
      std::lock_guard lock(mutex_);
      running_[*id] = runtime;
    }
    try {
      run_job(*id, runtime);
    } catch (const std::exception& e) {
      // A bug or a full disk: the job fails with a generic message; the details go to the log.
      std::fprintf(stderr, "penumbra serve: job %s: internal error: %s\n", id->c_str(), e.what());
      try {
        store_.mark_finished(*id, JobState::kFailed, unix_now(), "",
                             error_json("internal error while rendering; see the server log"));
      } catch (const std::exception&) {
      }
    }
    {
      std::lock_guard lock(mutex_);
      running_.erase(*id);
    }
    finished_cv_.notify_all();
  }
  {
    std::lock_guard lock(mutex_);
    --live_workers_;
  }
  workers_done_cv_.notify_all();
}

void JobService::run_job(const std::string& id, const std::shared_ptr<JobRuntime>& runtime) {
  {
    std::lock_guard lock(mutex_);  // ordered against cancel_or_delete
    auto record = store_.get(id);
    if (!record || record->state != JobState::kQueued) return;  // cancelled meanwhile
    if (record->attempts >= kMaxAttempts) {
      store_.mark_finished(id, JobState::kFailed, unix_now(), "",
                           error_json("the render was interrupted " + std::to_string(record->attempts) +
                                      " times (server crash or kill); not retried again"));
      return;
    }
    store_.mark_running(id, unix_now());
  }
  const auto scene = store_.scene(id);
  if (!scene) return;
  RenderJobOptions options;
  options.limits = config_.scene_limits();
  options.threads = config_.threads_per_job();
  options.max_render_seconds = config_.max_render_seconds;
  RenderOutcome outcome = run_render_job(*scene, options, *runtime);

  const double now = unix_now();
  switch (outcome.kind) {
    case RenderOutcome::Kind::kSucceeded: {
      const ImageMetadata meta = {
          {"penumbra:job", id},
          {"penumbra:spp", std::to_string(outcome.settings.spp)},
          {"penumbra:spp_mean", std::to_string(outcome.stats.spp_mean)},
          {"penumbra:render_seconds", std::to_string(outcome.stats.seconds)},
          {"penumbra:seed", std::to_string(outcome.settings.seed)},
          {"Software", api::kSoftwareName},
      };
      // Files first, then the record: a crash in between reruns the job, never serves a
      // missing file.
      files_.write(id, "exr", encode_image(outcome.image, ImageFormat::kExr, meta));
      files_.write(id, "png", encode_image(outcome.image, ImageFormat::kPng, meta));
      store_.mark_finished(id, JobState::kSucceeded, now, stats_json(outcome, options.threads), "");
      metrics_.observe_render("succeeded", outcome.stats.seconds, outcome.stats.rays);
      std::lock_guard lock(mutex_);
      const double total = outcome.stats.seconds + outcome.build_seconds;
      average_job_seconds_ = average_job_seconds_ > 0 ? 0.8 * average_job_seconds_ + 0.2 * total : total;
      break;
    }
    case RenderOutcome::Kind::kStopped:
      if (runtime->stop_reason() == JobRuntime::StopReason::kShutdown) {
        store_.requeue(id);  // runs again after the restart
      } else {
        store_.mark_finished(id, JobState::kCancelled, now, stats_json(outcome, options.threads), "");
        metrics_.observe_render("cancelled", outcome.stats.seconds, outcome.stats.rays);
      }
      break;
    case RenderOutcome::Kind::kFailed:
      store_.mark_finished(id, JobState::kFailed, now, "", error_json(outcome.error));
      metrics_.observe_render("failed", 0, 0);
      break;
  }
}

void JobService::expire_now() {
  for (const std::string& id : store_.expire(unix_now() - config_.retention_seconds)) files_.remove(id);
}

void JobService::reaper_loop() {
  const auto period = std::chrono::duration<double>(std::clamp(config_.retention_seconds / 4, 0.05, 60.0));
  std::unique_lock lock(reaper_mutex_);
  while (!stopping_) {
    reaper_cv_.wait_for(lock, period, [&] { return stopping_.load(); });
    if (stopping_) break;
    try {
      expire_now();
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
  std::lock_guard lock(mutex_);
  stopping_ = true;
  for (auto& [id, runtime] : running_) {
    const RenderProgress p = runtime->progress();
    const bool nearly_done = p.fraction > 0 && p.eta_seconds < kFinishAtShutdownSeconds;
    if (!nearly_done) runtime->request_stop(JobRuntime::StopReason::kShutdown);
  }
  queue_.close();
  finished_cv_.notify_all();
  {
    std::lock_guard rl(reaper_mutex_);
  }
  reaper_cv_.notify_all();
}

bool JobService::stop(std::chrono::steady_clock::time_point deadline) {
  bool all_done;
  {
    std::unique_lock lock(mutex_);
    all_done = workers_done_cv_.wait_until(lock, deadline, [&] { return live_workers_ == 0; });
  }
  if (!all_done) return false;  // a thread still runs (e.g. a scene build): the caller exits hard
  for (auto& t : workers_)
    if (t.joinable()) t.join();
  if (reaper_.joinable()) reaper_.join();
  return true;
}

Metrics::Gauges JobService::gauges() {
  Metrics::Gauges g;
  for (const auto& [state, n] : store_.count_by_state()) g.jobs_by_state[to_string(state)] = n;
  g.queue_depth = int64_t(queue_.size());
  g.queue_capacity = int64_t(queue_.capacity());
  {
    std::lock_guard lock(mutex_);
    g.running = int64_t(running_.size());
  }
  g.ready = accepting_;
  return g;
}

}  // namespace penumbra::server
