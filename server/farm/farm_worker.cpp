#include "server/farm/farm_worker.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "renderer/denoise/denoise_result.h"
#include "renderer/io/exr_window_file.h"
#include "renderer/io/image_io.h"
#include "renderer/io/layer_io.h"
#include "renderer/render/window_merge.h"
#include "server/farm/farm_render.h"
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

// The job fails (a task failed for good): its queued tasks are cancelled and its running ones
// told to stop at their next heartbeat (cancel_requested); their commits then find the job
// finished and change nothing.
void fail_job(PgConnection& db, const std::string& job, const std::string& why) {
  db.exec(
      "UPDATE jobs SET state = 'failed', finished_at = $2, error_json = $3, progress_json = '', "
      "cancel_requested = true WHERE id = $1 AND state IN ('queued', 'running')",
      {job, seconds(unix_now()), error_json(why)});
  db.exec("UPDATE tasks SET state = 'cancelled' WHERE job_id = $1 AND state = 'queued'", {job});
}

// The job goes back to 'queued' when the task given up was its only one under way: no other task
// of it is running or done (a split job with finished tiles stays running).
constexpr const char* kJobBackToQueue =
    "UPDATE jobs SET state = 'queued', progress_json = '' WHERE id = $1 AND state = 'running' AND "
    "NOT EXISTS (SELECT 1 FROM tasks o WHERE o.job_id = jobs.id AND o.id <> $2::bigint AND "
    "o.state IN ('running', 'done'))";

// The render statistics of several tasks of one job as the job's "stats": times, rays and samples
// added up (seconds is render time summed over the workers, not wall time), the least and most
// sampled pixel over all, the mean weighted by pixels; scene_builds: the tasks that read and built
// the scene (one per worker process that took part, unless a slot ran out of work in between).
nlohmann::json sum_task_stats(const std::vector<nlohmann::json>& parts) {
  double seconds_sum = 0, build = 0, spp_weighted = 0, pixels = 0;
  uint64_t rays = 0, camera_samples = 0;
  int spp_min = 0, spp_max = 0, threads = 0, scene_builds = 0;
  bool stopped = false;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const nlohmann::json& p = parts[i];
    seconds_sum += p.value("seconds", 0.0);
    build += p.value("build_seconds", 0.0);
    rays += p.value("rays", uint64_t(0));
    camera_samples += p.value("camera_samples", uint64_t(0));
    const int lo = p.value("spp_min", 0), hi = p.value("spp_max", 0);
    spp_min = i == 0 ? lo : std::min(spp_min, lo);
    spp_max = std::max(spp_max, hi);
    const double px = p.value("pixels", 0.0);
    spp_weighted += p.value("spp_mean", 0.0) * px;
    pixels += px;
    stopped = stopped || p.value("stopped_by_time_limit", false);
    threads = std::max(threads, p.value("threads", 0));
    if (!p.value("scene_reused", true)) ++scene_builds;
  }
  return nlohmann::ordered_json{{"seconds", seconds_sum},
                                {"build_seconds", build},
                                {"rays", rays},
                                {"mrays_per_second", seconds_sum > 0 ? rays / seconds_sum * 1e-6 : 0.0},
                                {"spp_mean", pixels > 0 ? spp_weighted / pixels : 0.0},
                                {"spp_min", spp_min},
                                {"spp_max", spp_max},
                                {"camera_samples", camera_samples},
                                {"stopped_by_time_limit", stopped},
                                {"threads", threads},
                                {"tasks", parts.size()},
                                {"scene_builds", scene_builds}};
}

std::vector<nlohmann::json> task_stats(PgConnection& db, const std::string& job,
                                       const std::string& kind) {
  PgRows rows = db.exec(
      "SELECT stats_json FROM tasks WHERE job_id = $1 AND kind = $2 AND state = 'done' ORDER BY id",
      {job, kind});
  std::vector<nlohmann::json> out;
  for (int i = 0; i < rows.size(); ++i) {
    nlohmann::json j = nlohmann::json::parse(rows.value(i, "stats_json"), nullptr, false);
    out.push_back(j.is_object() ? std::move(j) : nlohmann::json::object());
  }
  return out;
}

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
  KeptScene kept;
  while (!stopping_) {
    try {
      if (!db) {
        db = std::make_unique<PgConnection>(config_.store);
        db->listen(kTaskChannel);
      }
      reap_expired(*db);
      if (auto c = claim(*db)) {
        run(*db, *c, kept);
        continue;  // look again at once: more work may be queued
      }
      if (claimable_tasks_locked(*db)) {
        // Runnable tasks exist but were passed over: their job's row was locked for a moment
        // (another worker claiming or committing a task of the same job, a heartbeat, a
        // cancel). No NOTIFY will come for them, so look again shortly rather than sleeping
        // until the fallback poll: otherwise one worker takes every short task of a split job.
        std::this_thread::sleep_for(std::chrono::milliseconds(5 + std::rand() % 20));
        continue;
      }
      // Out of work: the last task's scene is not kept while the slot waits.
      kept = {};
      db->exec("UPDATE workers SET heartbeat_at = now() WHERE id = $1", {id_});
      db->wait_notification(kFallbackPollSeconds);
    } catch (const StoreError& e) {
      std::fprintf(stderr, "penumbra serve: worker %s: %s\n", id_.c_str(), e.what());
      db.reset();
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
}

bool FarmWorker::claimable_tasks_locked(PgConnection& db) {
  // The claim's conditions without its locks (a plain read waits for no lock).
  PgRows rows = db.exec(
      "SELECT EXISTS (SELECT 1 FROM tasks t JOIN jobs j ON j.id = t.job_id WHERE t.state = "
      "'queued' AND NOT j.cancel_requested AND j.state IN ('queued', 'running')) AS waiting");
  return rows.value(0, "waiting") == "t";
}

int FarmWorker::reap_expired(PgConnection& db) {
  // One statement: the expired tasks (locked, skipping any another worker is reaping), their
  // attempts marked, their jobs queued again, the tasks queued again.
  PgRows rows = db.exec(
      "WITH expired AS (SELECT id, job_id, lease_token, lease_owner FROM tasks "
      "  WHERE state = 'running' AND lease_expires < now() FOR UPDATE SKIP LOCKED), "
      "attempts AS (UPDATE task_attempts a SET outcome = 'lease_expired', ended_at = now() "
      "  FROM expired e WHERE a.lease_token = e.lease_token AND a.outcome = 'running'), "
      // A job is queued again when no other of its tasks is running or done (a split job whose
      // other tiles go on stays running).
      "jobs_back AS (UPDATE jobs j SET state = 'queued', progress_json = '' FROM expired e "
      "  WHERE j.id = e.job_id AND j.state = 'running' AND NOT EXISTS (SELECT 1 FROM tasks o "
      "  WHERE o.job_id = j.id AND o.state IN ('running', 'done') AND o.id NOT IN "
      "  (SELECT id FROM expired))) "
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
          "SELECT t.id, t.job_id, t.attempts, t.last_error, t.kind, t.params::text AS params, "
          "j.width, j.height, j.scene_json FROM tasks t "
          "JOIN jobs j ON j.id = t.job_id WHERE t.state = 'queued' AND NOT j.cancel_requested AND j.state IN ('queued', 'running') "
          "ORDER BY t.priority DESC, t.job_seq, t.id LIMIT 1 FOR UPDATE OF t, j SKIP LOCKED");
      if (rows.size() == 0) return;
      c.task = rows.int_value(0, "id");
      c.job = rows.value(0, "job_id");
      c.scene = rows.value(0, "scene_json");
      c.kind = rows.value(0, "kind");
      c.piece = task_piece_from_params(rows.value(0, "params"));
      c.width = int(rows.int_value(0, "width"));
      c.height = int(rows.int_value(0, "height"));
      const int attempts = int(rows.int_value(0, "attempts"));
      const std::string tid = std::to_string(c.task);
      if (attempts >= config_.max_attempts) {
        // Tried --max-attempts times (failures or lost workers): the job fails with the reason.
        step = Step::kExhausted;
        const std::string why = "the task was tried " + std::to_string(attempts) +
                                " times (--max-attempts); the last attempt: " +
                                rows.value(0, "last_error");
        db.exec("UPDATE tasks SET state = 'failed' WHERE id = $1", {tid});
        fail_job(db, c.job, why);
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
      // A job of several tasks is running from its first task's claim to its last commit.
      db.exec(
          "UPDATE jobs SET started_at = CASE WHEN state = 'running' THEN started_at ELSE $2 END, "
          "progress_json = CASE WHEN state = 'running' THEN progress_json ELSE '' END, "
          "state = 'running', attempts = attempts + 1 WHERE id = $1",
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
  // A tile's preview is its window's pixels beside the other tiles' (the API node places them).
  const std::string preview_path = c.piece.window
                                       ? tile_preview_path(config_.data_dir, c.job, *c.piece.window)
                                       : farm_preview_path(config_.data_dir, c.job);
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
      if (c.kind == "job") {
        db->exec("UPDATE jobs SET progress_json = $2 WHERE id = $1 AND state = 'running'",
                 {c.job, progress_to_json(runtime.progress())});
      } else if (c.kind != "merge") {
        const RenderProgress mine = runtime.progress();
        db->exec("UPDATE tasks SET progress_json = $2 WHERE id = $1 AND lease_token = $3",
                 {std::to_string(c.task), progress_to_json(mine), c.token});
        db->exec("UPDATE jobs SET progress_json = $2 WHERE id = $1 AND state = 'running'",
                 {c.job, job_progress_json(*db, c, mine)});
      }
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

std::string FarmWorker::job_progress_json(PgConnection& db, const Claim& c,
                                          const RenderProgress& mine) {
  // Samples of every task but this one (their last heartbeat, or all of them once done), plus
  // this one's now; over the samples of every frame of the job.
  PgRows rows = db.exec(
      "SELECT coalesce(sum(CASE WHEN progress_json = '' THEN 0 ELSE "
      "(progress_json::jsonb->>'samples_done')::numeric END), 0)::bigint AS done, "
      "(SELECT spp::bigint * width * height * greatest(frame_last - frame_first + 1, 1) "
      " FROM jobs WHERE id = $1) AS total, (SELECT started_at FROM jobs WHERE id = $1) AS started "
      "FROM tasks WHERE job_id = $1 AND id <> $2::bigint AND kind IN ('tile', 'frame')",
      {c.job, std::to_string(c.task)});
  RenderProgress p;
  p.samples_total = uint64_t(std::max<int64_t>(rows.int_value(0, "total"), 1));
  p.samples_done = std::min(p.samples_total, uint64_t(rows.int_value(0, "done")) + mine.samples_done);
  p.fraction = double(p.samples_done) / double(p.samples_total);
  p.elapsed_seconds = std::max(0.0, unix_now() - rows.double_value(0, "started"));
  p.eta_seconds = p.fraction > 0 ? p.elapsed_seconds * (1 - p.fraction) / p.fraction : 0.0;
  p.passes_done = mine.passes_done;
  return progress_to_json(p);
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

RenderOutcome FarmWorker::merge_tiles(PgConnection& db, const Claim& c, JobRuntime& runtime) {
  RenderOutcome out;
  // Only the committed attempts' files (tasks.result_token): a tile file left by a lost attempt
  // carries a token no row names and is never read.
  PgRows rows = db.exec(
      "SELECT params::text AS params, result_token, stats_json FROM tasks WHERE job_id = $1 AND "
      "kind = 'tile' AND state = 'done' ORDER BY id",
      {c.job});
  if (rows.size() == 0) throw std::runtime_error("no finished tiles to merge");
  std::vector<WindowPart> parts;
  std::vector<nlohmann::json> stats;
  for (int i = 0; i < rows.size(); ++i) {
    const std::string path =
        results_.path(c.job + "." + rows.value(i, "result_token"), kTileResultKey);
    ExrWindowFile file = read_exr_window(path);
    const TaskPiece piece = task_piece_from_params(rows.value(i, "params"));
    if (file.display.width() != c.width || file.display.height() != c.height || !piece.window ||
        !(*piece.window == file.part.window))
      throw std::runtime_error(path + ": not the window its task rendered");
    parts.push_back(std::move(file.part));
    nlohmann::json j = nlohmann::json::parse(rows.value(i, "stats_json"), nullptr, false);
    stats.push_back(j.is_object() ? std::move(j) : nlohmann::json::object());
  }
  if (runtime.cancel_flag()->load()) {
    out.kind = RenderOutcome::Kind::kStopped;
    return out;
  }
  const auto start = std::chrono::steady_clock::now();
  MergedImage merged = merge_windows(parts, c.width, c.height);
  parts.clear();
  RenderResult result;
  result.image = std::move(merged.image);
  result.layers = std::move(merged.layers);
  const nlohmann::json& first = stats.front();
  out.settings.width = c.width;
  out.settings.height = c.height;
  out.settings.spp = first.value("spp", 0);
  out.settings.seed = first.value("seed", uint64_t(0));
  out.settings.outputs = first.value("outputs", 0u);
  out.settings.denoise = first.value("denoise", false);
  // After the merge, as one machine denoises after its render (the tiles carry the guides).
  if (out.settings.denoise) denoise_result(out.settings.outputs, &result);
  const nlohmann::json sum = sum_task_stats(stats);
  out.stats.seconds = sum.value("seconds", 0.0);
  out.stats.spp_mean = sum.value("spp_mean", 0.0);
  out.stats.denoised = result.stats.denoised;
  out.stats.denoise_seconds = result.stats.denoise_seconds;
  out.stats.denoise_error = result.stats.denoise_error;
  out.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.image = std::move(result.image);
  out.layers = std::move(result.layers);
  out.kind = RenderOutcome::Kind::kSucceeded;
  return out;
}

RenderOutcome FarmWorker::render_piece(const Claim& c, const RenderJobOptions& options,
                                       JobRuntime& runtime, KeptScene& kept) {
  const std::string key = scene_cache_key(c.job, c.piece.frame);
  // Another scene's: let it go before this one is read and built, unless another task holds it.
  if (kept.key != key) kept = {};
  const SceneCache::Lookup scene = scenes_.get(key, [&](std::string& error) {
    return prepare_piece_scene(c.scene, options, c.piece, error);
  });
  metrics_.count_scene_preparation(!scene.scene ? "failed" : scene.reused ? "reused" : "built");
  if (!scene.scene) {
    RenderOutcome failed;
    failed.error = scene.error;
    return failed;
  }
  kept = {key, scene.scene};
  return render_farm_piece(*scene.scene, !scene.reused, options, runtime, c.piece);
}

void FarmWorker::run(PgConnection& db, const Claim& c, KeptScene& kept) {
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
    if (c.kind == "merge" || c.kind == "job") kept = {};  // no piece of a kept scene
    if (c.kind == "merge")
      outcome = merge_tiles(db, c, *runtime);
    else if (c.kind == "job")
      outcome = run_render_job(c.scene, options, *runtime);
    else
      outcome = render_piece(c, options, *runtime, kept);
  } catch (const std::exception& e) {
    outcome.kind = RenderOutcome::Kind::kFailed;
    outcome.error = std::string(c.kind == "merge" ? "cannot merge the tiles: "
                                                  : "internal error while rendering: ") +
                    e.what();
  }
  // Results are written under this attempt's token before the commit: a name no other attempt
  // uses, so a late worker never overwrites the committed files.
  const std::string result_id = c.job + "." + c.token;
  if (outcome.kind == RenderOutcome::Kind::kSucceeded && !lease_lost) {
    try {
      ImageMetadata meta = result_metadata(c.job, outcome);
      if (c.kind == "tile") {
        // As `penumbra render --window` writes it: the frame as display window, the tile as
        // data window, beauty and layers in float.
        const PixelWindow display{0, 0, c.width, c.height};
        results_.write(result_id, kTileResultKey,
                       encode_layered_exr(outcome.image, outcome.layers, ExrLayout::kPlain, meta,
                                          &*c.piece.window, &display));
        // The finished tile stays in the job's preview until the merge.
        write_image_file(tile_preview_path(config_.data_dir, c.job, *c.piece.window),
                         outcome.image);
      } else {
        if (c.piece.frame) meta.emplace_back("penumbra:frame", std::to_string(*c.piece.frame));
        if (c.kind == "merge") meta.emplace_back("penumbra:merged_parts", "tiles");
        write_results(results_, result_id, outcome.image, outcome.layers, meta);
      }
    } catch (const std::exception& e) {
      outcome.kind = RenderOutcome::Kind::kFailed;
      outcome.error = std::string("cannot write the result: ") + e.what();
    }
  }
  done = true;
  heartbeat.join();
  std::error_code ignored;
  if (!c.piece.window) std::filesystem::remove(farm_preview_path(config_.data_dir, c.job), ignored);
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
  // A task of a job of several: the job's row is locked first, so the commits of its tasks take
  // turns and exactly one of them sees the last tile (or frame) done.
  bool cancel_requested = false;
  const auto lock_job = [&]() -> std::string {
    PgRows j = db.exec("SELECT state, cancel_requested FROM jobs WHERE id = $1 FOR UPDATE", {c.job});
    cancel_requested = j.size() && j.value(0, "cancel_requested") == "t";
    return j.size() ? j.value(0, "state") : std::string();
  };
  const auto job_live = [](const std::string& state) {
    return state == "queued" || state == "running";
  };
  const bool shutdown = outcome.kind == RenderOutcome::Kind::kStopped &&
                        runtime->stop_reason() == JobRuntime::StopReason::kShutdown;
  // A piece's statistics, kept on its task for the job's sum (and the merge's settings).
  nlohmann::json piece_stats = nlohmann::json::parse(render_stats_json(outcome, options.threads));
  piece_stats["pixels"] = c.piece.window ? c.piece.window->pixel_count()
                                         : int64_t(c.width) * int64_t(c.height);
  piece_stats["spp"] = outcome.settings.spp;
  piece_stats["seed"] = outcome.settings.seed;
  piece_stats["outputs"] = outcome.settings.outputs;
  piece_stats["denoise"] = outcome.settings.denoise;
  RenderProgress finished = runtime->progress();
  finished.samples_done = finished.samples_total;
  finished.fraction = 1;
  bool committed = false;
  if (lease_lost) {
    committed = false;
  } else if (shutdown) {
    // Back to the queue for another worker now; this attempt does not count.
    committed = commit_with_retry(db, [&] {
      if (c.kind != "job") lock_job();
      mine = db.exec(std::string(kStillMine), {tid, c.token, "queued", ""}).affected() > 0;
      if (!mine) return;
      db.exec("UPDATE tasks SET attempts = greatest(attempts - 1, 0), progress_json = '' "
              "WHERE id = $1", {tid});
      db.exec("UPDATE jobs SET attempts = greatest(attempts - 1, 0) WHERE id = $1", {c.job});
      db.exec(kJobBackToQueue, {c.job, tid});
      end_attempt("shutdown");
      db.exec(std::string("NOTIFY ") + kTaskChannel);
      db.exec(std::string("NOTIFY ") + kJobChannel);
    });
  } else {
    committed = commit_with_retry(db, [&] {
      final_state.clear();
      const std::string job_state = c.kind != "job" ? lock_job() : std::string("running");
      // This task ends cancelled, and its job with it while the job is live (its queued tasks
      // too); `stats`: the job's statistics to record, nullopt to keep them. False when there is
      // nothing more to write (the lease is gone, or the job had already ended).
      const auto end_cancelled = [&](const std::optional<std::string>& stats) {
        mine = db.exec(std::string(kStillMine), {tid, c.token, "cancelled", ""}).affected() > 0;
        if (!mine) return false;
        end_attempt("cancelled");
        if (!job_live(job_state)) return false;
        final_state = "cancelled";
        if (stats)
          db.exec("UPDATE jobs SET state = 'cancelled', finished_at = $2, stats_json = $3, "
                  "progress_json = '' WHERE id = $1",
                  {c.job, now, *stats});
        else
          db.exec("UPDATE jobs SET state = 'cancelled', finished_at = $2, progress_json = '' "
                  "WHERE id = $1",
                  {c.job, now});
        db.exec("UPDATE tasks SET state = 'cancelled' WHERE job_id = $1 AND state = 'queued'",
                {c.job});
        return true;
      };
      switch (outcome.kind) {
        case RenderOutcome::Kind::kSucceeded:
          if (c.kind != "job" && (!job_live(job_state) || cancel_requested)) {
            // The job failed or was cancelled meanwhile: this piece counts for nothing. A cancel
            // that reached no heartbeat of this task (it finished first) ends the job here,
            // before a merge could be queued that no claim would take.
            if (!end_cancelled(std::nullopt)) return;
            break;
          }
          mine = db.exec(std::string(kStillMine), {tid, c.token, "done", ""}).affected() > 0;
          if (!mine) return;
          end_attempt("succeeded");
          db.exec("UPDATE workers SET tasks_succeeded = tasks_succeeded + 1 WHERE id = $1", {id_});
          if (c.kind == "job" || c.kind == "merge") {
            final_state = "succeeded";
            const std::string stats =
                c.kind == "job" ? render_stats_json(outcome, options.threads) : [&] {
                  nlohmann::json s = sum_task_stats(task_stats(db, c.job, "tile"));
                  if (outcome.settings.denoise) {
                    s["denoised"] = outcome.stats.denoised;
                    s["denoise_seconds"] = outcome.stats.denoise_seconds;
                    if (!outcome.stats.denoise_error.empty())
                      s["denoise_error"] = outcome.stats.denoise_error;
                  }
                  s["merge_seconds"] = outcome.build_seconds;
                  return s.dump();
                }();
            db.exec(
                "UPDATE jobs SET state = 'succeeded', finished_at = $2, stats_json = $3, "
                "error_json = '', result_token = $4, progress_json = '' WHERE id = $1",
                {c.job, now, stats, c.token});
            if (c.kind == "merge") db.exec("UPDATE tasks SET result_token = $2 WHERE id = $1",
                                           {tid, c.token});
            break;
          }
          // A tile or a frame: its files are named by its token; the job moves on when it was
          // the last.
          db.exec(
              "UPDATE tasks SET result_token = $2, progress_json = $3, stats_json = $4 WHERE id = $1",
              {tid, c.token, progress_to_json(finished), piece_stats.dump()});
          if (c.kind == "frame")
            db.exec("UPDATE jobs SET frames_done = frames_done + 1 WHERE id = $1", {c.job});
          if (db.exec("SELECT 1 FROM tasks WHERE job_id = $1 AND kind = $2 AND state <> 'done' "
                      "LIMIT 1",
                      {c.job, c.kind})
                  .size() > 0)
            break;
          if (c.kind == "tile") {
            // The last tile: the merge is queued in this same transaction, for any worker.
            db.exec(
                "INSERT INTO tasks (job_id, kind, params, priority, job_seq) SELECT id, 'merge', "
                "'{}', priority, seq FROM jobs WHERE id = $1",
                {c.job});
            db.exec(std::string("NOTIFY ") + kTaskChannel);
          } else {
            final_state = "succeeded";
            db.exec(
                "UPDATE jobs SET state = 'succeeded', finished_at = $2, stats_json = $3, "
                "error_json = '', progress_json = '' WHERE id = $1",
                {c.job, now, sum_task_stats(task_stats(db, c.job, "frame")).dump()});
          }
          break;
        case RenderOutcome::Kind::kStopped:
          if (!end_cancelled(render_stats_json(outcome, options.threads))) return;
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
          if (!job_live(job_state)) return;
          if (last) {
            final_state = "failed";
            fail_job(db, c.job, outcome.error);
          } else {
            db.exec("UPDATE tasks SET progress_json = '' WHERE id = $1", {tid});
            db.exec(kJobBackToQueue, {c.job, tid});
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
    remove_attempt_files(config_.data_dir, c.job, c.token);
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
  if (c.kind == "merge" && final_state == "succeeded") {
    // The tiles are in the job's result now: their files and previews go.
    try {
      PgRows tiles = db.exec(
          "SELECT result_token FROM tasks WHERE job_id = $1 AND kind = 'tile' AND state = 'done'",
          {c.job});
      for (int i = 0; i < tiles.size(); ++i)
        remove_attempt_files(config_.data_dir, c.job, tiles.value(i, "result_token"));
    } catch (const StoreError&) {
      // Left for the retention sweep, which removes every file of the job.
    }
    for (const auto& [window, path] : tile_previews(config_.data_dir, c.job))
      std::filesystem::remove(path, ignored);
  }
  // Per task, as a single node counts per job.
  if (!final_state.empty() || outcome.kind == RenderOutcome::Kind::kSucceeded)
    metrics_.observe_render(final_state.empty() ? "succeeded" : final_state,
                            outcome.stats.seconds, outcome.stats.rays);
}

}  // namespace penumbra::server
