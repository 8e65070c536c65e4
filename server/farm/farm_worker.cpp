#include "server/farm/farm_worker.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "renderer/io/image_io.h"
#include "server/farm/farm_job_row.h"
#include "server/farm/farm_service.h"
#include "server/jobs/unix_time.h"
#include "server/storage/asset_store.h"
#include "server/storage/result_files.h"

namespace penumbra::server {
namespace {

// Idle slots look for work this often even without a notification (one may be missed while
// the connection is reopened), and reap expired leases as often.
constexpr double kFallbackPollSeconds = 2.0;

std::string random_hex(int digits) {
  static thread_local std::random_device rd;
  static const char* kHex = "0123456789abcdef";
  std::string s;
  while (int(s.size()) < digits) {
    const uint32_t v = rd();
    for (int k = 0; k < 8 && int(s.size()) < digits; ++k) s += kHex[(v >> (k * 4)) & 15];
  }
  return s;
}

std::string error_json(const std::string& detail) {
  return nlohmann::ordered_json{{"detail", detail}}.dump();
}

std::string seconds(double s) { return std::to_string(s); }

}  // namespace

FarmWorker::FarmWorker(const ServerConfig& config, FileResultStore& results, Metrics& metrics)
    : config_(config), results_(results), metrics_(metrics) {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  host_ = host;
  // Unique across restarts and hosts; readable in GET /v1/workers.
  id_ = host_ + "-" + std::to_string(::getpid()) + "-" + random_hex(6);
}

FarmWorker::~FarmWorker() {
  begin_shutdown();
  join();
}

void FarmWorker::start() {
  PgConnection db(config_.store);
  db.exec(
      "INSERT INTO workers (id, host, pid, slots, render_threads) VALUES ($1, $2, $3, $4, $5)",
      {id_, host_, std::to_string(::getpid()),
       std::to_string(config_.workers), std::to_string(config_.threads_per_job())});
  for (int i = 0; i < config_.workers; ++i) slots_.emplace_back([this] { slot_loop(); });
}

void FarmWorker::begin_shutdown() {
  stopping_ = true;
  std::lock_guard lock(runtimes_mutex_);
  for (const auto& r : runtimes_) r->request_stop(JobRuntime::StopReason::kShutdown);
}

void FarmWorker::join() {
  for (auto& t : slots_)
    if (t.joinable()) t.join();
  slots_.clear();
  try {
    PgConnection db(config_.store);
    db.exec("UPDATE workers SET stopped_at = now() WHERE id = $1", {id_});
  } catch (const StoreError&) {
    // The row stays; its heartbeat ages and GET /v1/workers shows it as not alive.
  }
}

void FarmWorker::slot_loop() {
  std::unique_ptr<PgConnection> db;
  while (!stopping_) {
    try {
      if (!db) {
        db = std::make_unique<PgConnection>(config_.store);
        db->listen(kTaskChannel);
      }
      reap_expired(*db);
      if (auto c = claim(*db)) {
        run(*db, *c);
        continue;  // look again at once: more work may be queued
      }
      db->exec("UPDATE workers SET heartbeat_at = now() WHERE id = $1", {id_});
      db->wait_notification(kFallbackPollSeconds);
    } catch (const StoreError& e) {
      std::fprintf(stderr, "penumbra serve: worker %s: %s\n", id_.c_str(), e.what());
      db.reset();
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
}

int FarmWorker::reap_expired(PgConnection& db) {
  // One statement: the expired tasks (locked, skipping any another worker is reaping), their
  // attempts marked, their jobs queued again, the tasks queued again.
  PgRows rows = db.exec(
      "WITH expired AS (SELECT id, job_id, lease_token, lease_owner FROM tasks "
      "  WHERE state = 'running' AND lease_expires < now() FOR UPDATE SKIP LOCKED), "
      "attempts AS (UPDATE task_attempts a SET outcome = 'lease_expired', ended_at = now() "
      "  FROM expired e WHERE a.lease_token = e.lease_token AND a.outcome = 'running'), "
      "jobs_back AS (UPDATE jobs j SET state = 'queued', progress_json = '' FROM expired e "
      "  WHERE j.id = e.job_id AND j.state = 'running') "
      "UPDATE tasks t SET state = 'queued', lease_token = NULL, lease_expires = NULL, "
      "  last_error = 'the worker ' || e.lease_owner || ' stopped renewing its lease' "
      "FROM expired e WHERE t.id = e.id RETURNING t.id");
  // Workers silent for ten leases are gone (kill -9, lost host): off /v1/workers and /metrics.
  db.exec(
      "UPDATE workers SET stopped_at = now() WHERE stopped_at IS NULL AND heartbeat_at < now() - "
      "make_interval(secs => $1)",
      {seconds(10 * config_.lease_seconds)});
  if (rows.size() > 0) {
    std::fprintf(stderr, "penumbra serve: worker %s: %d task(s) of lost workers queued again\n",
                 id_.c_str(), rows.size());
    db.exec(std::string("NOTIFY ") + kTaskChannel);
    db.exec(std::string("NOTIFY ") + kJobChannel);
  }
  return rows.size();
}

std::optional<FarmWorker::Claim> FarmWorker::claim(PgConnection& db) {
  while (!stopping_) {
    enum class Step { kNone, kClaimed, kExhausted } step = Step::kNone;
    Claim c;
    db.transaction([&] {
      // Run order as on one node; SKIP LOCKED: concurrent claimers each take a different task,
      // and a job an API node is cancelling (its row locked) is passed over, never waited on:
      // a claimer holds no lock while it waits, so it can take part in no deadlock.
      PgRows rows = db.exec(
          "SELECT t.id, t.job_id, t.attempts, t.last_error, j.scene_json FROM tasks t "
          "JOIN jobs j ON j.id = t.job_id WHERE t.state = 'queued' "
          "ORDER BY t.priority DESC, t.job_seq, t.id LIMIT 1 FOR UPDATE OF t, j SKIP LOCKED");
      if (rows.size() == 0) return;
      c.task = rows.int_value(0, "id");
      c.job = rows.value(0, "job_id");
      c.scene = rows.value(0, "scene_json");
      const int attempts = int(rows.int_value(0, "attempts"));
      const std::string tid = std::to_string(c.task);
      if (attempts >= config_.max_attempts) {
        // Tried --max-attempts times (failures or lost workers): the job fails with the reason.
        step = Step::kExhausted;
        const std::string why = "the task was tried " + std::to_string(attempts) +
                                " times (--max-attempts); the last attempt: " +
                                rows.value(0, "last_error");
        db.exec("UPDATE tasks SET state = 'failed' WHERE id = $1", {tid});
        db.exec(
            "UPDATE jobs SET state = 'failed', finished_at = $2, error_json = $3, "
            "progress_json = '' WHERE id = $1 AND state IN ('queued', 'running')",
            {c.job, seconds(unix_now()), error_json(why)});
        db.exec(std::string("NOTIFY ") + kJobChannel);
        return;
      }
      step = Step::kClaimed;
      c.token = random_hex(24);
      c.attempt = attempts + 1;
      db.exec(
          "UPDATE tasks SET state = 'running', attempts = attempts + 1, lease_token = $2, "
          "lease_owner = $3, lease_expires = now() + make_interval(secs => $4) WHERE id = $1",
          {tid, c.token, id_, seconds(config_.lease_seconds)});
      db.exec(
          "UPDATE jobs SET state = 'running', started_at = $2, attempts = attempts + 1, "
          "progress_json = '' WHERE id = $1",
          {c.job, seconds(unix_now())});
      db.exec(
          "INSERT INTO task_attempts (task_id, job_id, worker, lease_token) VALUES ($1, $2, $3, "
          "$4)",
          {tid, c.job, id_, c.token});
      db.exec(std::string("NOTIFY ") + kJobChannel);
    });
    if (step == Step::kNone) return std::nullopt;
    if (step == Step::kClaimed) return c;
    metrics_.observe_render("failed", 0, 0);
  }
  return std::nullopt;
}

void FarmWorker::heartbeat_loop(const Claim& c, JobRuntime& runtime, std::atomic<bool>& done,
                                std::atomic<bool>& lease_lost) {
  std::unique_ptr<PgConnection> db;
  std::shared_ptr<const Image> written;  // the preview last written
  const std::string preview_path = farm_preview_path(config_.data_dir, c.job);
  const auto period = std::chrono::duration<double>(config_.heartbeat_seconds);
  auto next = std::chrono::steady_clock::now() + period;
  while (!done) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (std::chrono::steady_clock::now() < next) continue;
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    try {
      if (!db) db = std::make_unique<PgConnection>(config_.store);
      // Renewed only while this claim's token still holds it (and has not expired: a reaper
      // may already have given the task to someone else).
      PgRows rows = db->exec(
          "UPDATE tasks SET lease_expires = now() + make_interval(secs => $3) WHERE id = $1 "
          "AND lease_token = $2 AND state = 'running' AND lease_expires > now() "
          "RETURNING (SELECT cancel_requested FROM jobs WHERE jobs.id = tasks.job_id) AS cancel",
          {std::to_string(c.task), c.token, seconds(config_.lease_seconds)});
      if (rows.size() == 0) {
        std::fprintf(stderr, "penumbra serve: worker %s: lost the lease of task %lld; stopping it\n",
                     id_.c_str(), static_cast<long long>(c.task));
        lease_lost = true;
        runtime.request_stop(JobRuntime::StopReason::kShutdown);
        return;
      }
      if (rows.value(0, "cancel") == "t") runtime.request_stop(JobRuntime::StopReason::kUserCancel);
      db->exec("UPDATE jobs SET progress_json = $2 WHERE id = $1 AND state = 'running'",
               {c.job, progress_to_json(runtime.progress())});
      db->exec("UPDATE workers SET heartbeat_at = now() WHERE id = $1", {id_});
      if (auto image = runtime.preview(); image && image != written) {
        try {
          write_image_file(preview_path, *image);
          written = image;
        } catch (const std::exception& e) {
          std::fprintf(stderr, "penumbra serve: worker %s: preview: %s\n", id_.c_str(), e.what());
        }
      }
    } catch (const StoreError& e) {
      // The database is away: the render goes on; the commit decides whether it still counts.
      std::fprintf(stderr, "penumbra serve: worker %s: heartbeat: %s\n", id_.c_str(), e.what());
      db.reset();
    }
  }
}

bool FarmWorker::commit_with_retry(PgConnection& db, const std::function<void()>& commit) {
  const auto give_up = std::chrono::steady_clock::now() +
                       std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                           std::chrono::duration<double>(config_.lease_seconds));
  while (true) {
    try {
      db.transaction(commit);
      return true;
    } catch (const StoreError& e) {
      if (std::chrono::steady_clock::now() >= give_up) {
        std::fprintf(stderr, "penumbra serve: worker %s: cannot commit: %s\n", id_.c_str(), e.what());
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
}

void FarmWorker::run(PgConnection& db, const Claim& c) {
  auto runtime = std::make_shared<JobRuntime>();
  {
    std::lock_guard lock(runtimes_mutex_);
    if (stopping_) runtime->request_stop(JobRuntime::StopReason::kShutdown);
    runtimes_.push_back(runtime);
  }
  std::atomic<bool> done{false}, lease_lost{false};
  std::thread heartbeat([&] { heartbeat_loop(c, *runtime, done, lease_lost); });

  RenderJobOptions options;
  options.limits = config_.scene_limits();
  options.threads = config_.threads_per_job();
  options.max_render_seconds = config_.max_render_seconds;
  options.assets.root = job_asset_folder(config_.data_dir, c.job);
  options.assets.max_file_bytes = int64_t(config_.max_asset_bytes);
  if (std::error_code ec; !std::filesystem::is_directory(options.assets.root, ec))
    options.assets.root.clear();
  RenderOutcome outcome;
  try {
    outcome = run_render_job(c.scene, options, *runtime);
  } catch (const std::exception& e) {
    outcome.kind = RenderOutcome::Kind::kFailed;
    outcome.error = std::string("internal error while rendering: ") + e.what();
  }
  // Results are written under this attempt's token before the commit: a name no other attempt
  // uses, so a late worker never overwrites the committed files.
  const std::string result_id = c.job + "." + c.token;
  if (outcome.kind == RenderOutcome::Kind::kSucceeded && !lease_lost) {
    try {
      write_results(results_, result_id, outcome.image, outcome.layers,
                    result_metadata(c.job, outcome));
    } catch (const std::exception& e) {
      outcome.kind = RenderOutcome::Kind::kFailed;
      outcome.error = std::string("cannot write the result: ") + e.what();
    }
  }
  done = true;
  heartbeat.join();
  std::error_code ignored;
  std::filesystem::remove(farm_preview_path(config_.data_dir, c.job), ignored);
  {
    std::lock_guard lock(runtimes_mutex_);
    runtimes_.erase(std::find(runtimes_.begin(), runtimes_.end(), runtime));
  }

  const std::string tid = std::to_string(c.task);
  const std::string now = seconds(unix_now());
  // Every commit below holds only while this claim still holds an unexpired lease.
  const char* kStillMine =
      "UPDATE tasks SET state = $3, lease_token = NULL, lease_expires = NULL, last_error = $4 "
      "WHERE id = $1 AND lease_token = $2 AND state = 'running' AND lease_expires > now()";
  bool mine = false;
  std::string final_state;
  const auto end_attempt = [&](const std::string& outcome_name) {
    db.exec(
        "UPDATE task_attempts SET outcome = $2, ended_at = now() WHERE lease_token = $1",
        {c.token, outcome_name});
  };
  const bool shutdown = outcome.kind == RenderOutcome::Kind::kStopped &&
                        runtime->stop_reason() == JobRuntime::StopReason::kShutdown;
  bool committed = false;
  if (lease_lost) {
    committed = false;
  } else if (shutdown) {
    // Back to the queue for another worker now; this attempt does not count.
    committed = commit_with_retry(db, [&] {
      mine = db.exec(std::string(kStillMine), {tid, c.token, "queued", ""}).affected() > 0;
      if (!mine) return;
      db.exec("UPDATE tasks SET attempts = greatest(attempts - 1, 0) WHERE id = $1", {tid});
      db.exec(
          "UPDATE jobs SET state = 'queued', attempts = greatest(attempts - 1, 0), "
          "progress_json = '' WHERE id = $1 AND state = 'running'",
          {c.job});
      end_attempt("shutdown");
      db.exec(std::string("NOTIFY ") + kTaskChannel);
      db.exec(std::string("NOTIFY ") + kJobChannel);
    });
  } else {
    committed = commit_with_retry(db, [&] {
      switch (outcome.kind) {
        case RenderOutcome::Kind::kSucceeded:
          mine = db.exec(std::string(kStillMine), {tid, c.token, "done", ""}).affected() > 0;
          if (!mine) return;
          final_state = "succeeded";
          db.exec(
              "UPDATE jobs SET state = 'succeeded', finished_at = $2, stats_json = $3, "
              "error_json = '', result_token = $4, progress_json = '' WHERE id = $1",
              {c.job, now, render_stats_json(outcome, options.threads), c.token});
          end_attempt("succeeded");
          db.exec("UPDATE workers SET tasks_succeeded = tasks_succeeded + 1 WHERE id = $1", {id_});
          break;
        case RenderOutcome::Kind::kStopped:
          mine = db.exec(std::string(kStillMine), {tid, c.token, "cancelled", ""}).affected() > 0;
          if (!mine) return;
          final_state = "cancelled";
          db.exec(
              "UPDATE jobs SET state = 'cancelled', finished_at = $2, stats_json = $3, "
              "progress_json = '' WHERE id = $1",
              {c.job, now, render_stats_json(outcome, options.threads)});
          end_attempt("cancelled");
          break;
        case RenderOutcome::Kind::kFailed: {
          // Tried again (another worker may have what this one lacks) until --max-attempts.
          const bool last = c.attempt >= config_.max_attempts;
          mine = db.exec(std::string(kStillMine),
                         {tid, c.token, last ? "failed" : "queued", outcome.error})
                     .affected() > 0;
          if (!mine) return;
          end_attempt("failed");
          db.exec("UPDATE workers SET tasks_failed = tasks_failed + 1 WHERE id = $1", {id_});
          if (last) {
            final_state = "failed";
            db.exec(
                "UPDATE jobs SET state = 'failed', finished_at = $2, error_json = $3, "
                "progress_json = '' WHERE id = $1",
                {c.job, now, error_json(outcome.error)});
          } else {
            db.exec("UPDATE jobs SET state = 'queued', progress_json = '' WHERE id = $1", {c.job});
            db.exec(std::string("NOTIFY ") + kTaskChannel);
          }
          break;
        }
      }
      db.exec(std::string("NOTIFY ") + kJobChannel);
    });
  }
  if (!committed || !mine) {
    // Someone else owns the task now (or nobody could be told): this attempt's files are never
    // served; they go.
    results_.remove(result_id);
    std::fprintf(stderr,
                 "penumbra serve: worker %s: task %lld of job %s: the lease was lost; the "
                 "attempt's result is discarded\n",
                 id_.c_str(), static_cast<long long>(c.task), c.job.c_str());
    try {
      db.exec(
          "UPDATE task_attempts SET outcome = 'lease_lost', ended_at = now() WHERE lease_token = "
          "$1 AND outcome = 'running'",
          {c.token});
    } catch (const StoreError&) {
    }
    return;
  }
  if (final_state == "succeeded") {
    metrics_.observe_render("succeeded", outcome.stats.seconds, outcome.stats.rays);
  } else if (!final_state.empty()) {
    metrics_.observe_render(final_state, outcome.stats.seconds, outcome.stats.rays);
  }
}

}  // namespace penumbra::server
