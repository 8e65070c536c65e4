#include "server/farm/farm_service.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <unordered_map>

#include "renderer/io/image_io.h"
#include "server/farm/farm_job_row.h"
#include "server/farm/farm_tasks.h"
#include "server/jobs/submission_check.h"
#include "server/jobs/unix_time.h"
#include "server/storage/disk_space.h"

namespace penumbra::server {
namespace {

std::string param(int64_t v) { return std::to_string(v); }
// Unix seconds with their fraction (std::to_string keeps 6 decimals).
std::string seconds_text(double s) { return std::to_string(s); }

constexpr const char* kLiveStates = "('queued','running')";

}  // namespace

FarmService::FarmService(const ServerConfig& config, PgPool& pool, FileResultStore& results,
                         Metrics& metrics, AssetStore* assets)
    : config_(config), pool_(pool), results_(results), metrics_(metrics), assets_(assets) {
  std::filesystem::create_directories(std::filesystem::path(config_.data_dir) / "previews");
  if (assets_) {
    // An asset may be evicted only when no queued or running job of the farm names it.
    assets_->set_job_liveness([this](const std::string& id) {
      try {
        auto db = pool_.acquire();
        return db->exec(std::string("SELECT 1 FROM jobs WHERE id = $1 AND state IN ") +
                            kLiveStates,
                        {id})
                   .size() > 0;
      } catch (const StoreError&) {
        return true;  // unknown: keep the files
      }
    });
  }
}

FarmService::~FarmService() {
  begin_shutdown();
  stop();
}

void FarmService::start() {
  event_thread_ = std::thread([this] { event_loop(); });
  reaper_ = std::thread([this] { reaper_loop(); });
}

void FarmService::expire_now() {
  auto db = pool_.acquire();
  PgRows gone = db->exec(
      "DELETE FROM jobs WHERE state IN ('succeeded', 'failed', 'cancelled', 'deleted') AND "
      "finished_at > 0 AND finished_at < $1 RETURNING id",
      {seconds_text(unix_now() - config_.retention_seconds)});
  // Rows first, then files: a crash in between leaves files nobody serves, never a record
  // whose image is gone.
  for (int i = 0; i < gone.size(); ++i) {
    const std::string id = gone.value(i, "id");
    // Every attempt's files: the result, a split job's tiles, an animation's frames, and those
    // of attempts that lost their lease between writing and committing.
    remove_job_files(config_.data_dir, id);
    events_.forget(id);
    if (assets_) assets_->remove_job_folder(id);
  }
}

void FarmService::reaper_loop() {
  const auto period = std::chrono::duration<double>(
      std::clamp(config_.retention_seconds / 4, 0.05, 60.0));
  auto next = std::chrono::steady_clock::now();
  while (!stopping_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (std::chrono::steady_clock::now() < next) continue;
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    try {
      expire_now();
    } catch (const StoreError& e) {
      std::fprintf(stderr, "penumbra serve: expiry: %s\n", e.what());
    }
  }
}

void FarmService::begin_shutdown() {
  stopping_ = true;
  events_.wake_all();
}

void FarmService::stop() {
  if (event_thread_.joinable()) event_thread_.join();
  if (reaper_.joinable()) reaper_.join();
}

SubmitOutcome FarmService::submit(std::string_view body, const std::string& idempotency_key) {
  SubmitOutcome out;
  if (stopping_) {
    out.kind = SubmitOutcome::Kind::kNotAccepting;
    out.retry_after_seconds = 5;
    return out;
  }
  PreparedSubmission prepared = prepare_submission(config_, assets_, body, idempotency_key);
  if (prepared.refusal) return std::move(*prepared.refusal);
  out.warnings = prepared.warnings;
  JobRecord r = std::move(prepared.record);
  if (!r.notify.url.empty()) {
    // Said plainly rather than accepted and never sent.
    out.kind = SubmitOutcome::Kind::kInvalid;
    out.errors.push_back({"/notify", "webhooks are not delivered by the PostgreSQL store yet "
                                     "(docs/scale-out.md); submit without \"notify\""});
    return out;
  }
  if (const auto available = available_bytes(config_.data_dir)) {
    const std::uint64_t needed = prepared.worst_case_bytes + body.size() + config_.min_free_bytes;
    if (*available < needed) {
      out.kind = SubmitOutcome::Kind::kNoSpace;
      out.bytes_needed = needed;
      out.bytes_available = *available;
      return out;
    }
  }
  // An existing job under the key: the same submission (replay) or another (422).
  auto existing_by_key = [&](PgConnection& db) -> std::optional<SubmitOutcome> {
    if (idempotency_key.empty()) return std::nullopt;
    PgRows rows = db.exec(std::string("SELECT ") + kJobColumns +
                              ", scene_json FROM jobs WHERE idempotency_key = $1 AND state <> "
                              "'deleted'",
                          {idempotency_key});
    if (rows.size() == 0) return std::nullopt;
    SubmitOutcome o;
    o.record = job_from_row(rows, 0);
    const bool same = rows.value(0, "scene_json") == prepared.scene_json &&
                      o.record.priority == r.priority;
    o.kind = same ? SubmitOutcome::Kind::kReplayed : SubmitOutcome::Kind::kKeyReused;
    return o;
  };
  // The job's tasks (farm_tasks.h): an animation's frames, a large still's tiles, or one task.
  const JobShape shape = read_job_shape(prepared.scene_json, config_.scene_limits().max_json_depth);
  std::vector<PixelWindow> tiles;
  if (shape.frames) {
    r.frame_first = int(shape.frames->first);
    r.frame_last = int(shape.frames->second);
    r.samples_total = uint64_t(r.width) * uint64_t(r.height) * uint64_t(r.spp) *
                      uint64_t(r.frame_count());
  } else if (shape.splittable) {
    tiles = tile_windows(r.width, r.height, config_.tile_pixels);
  }
  nlohmann::json tile_params = nlohmann::json::array();
  for (const PixelWindow& w : tiles)
    tile_params.push_back(nlohmann::json::parse(task_params_json(TaskPiece{std::nullopt, w})));
  try {
    auto db = pool_.acquire();
    std::optional<SubmitOutcome> decided = db->transaction([&]() -> std::optional<SubmitOutcome> {
      if (auto existing = existing_by_key(*db)) return existing;
      PgRows queued = db->exec("SELECT count(*) AS n FROM jobs WHERE state = 'queued'");
      if (queued.int_value(0, "n") >= config_.max_queue) {
        SubmitOutcome o;
        o.kind = SubmitOutcome::Kind::kQueueFull;
        o.retry_after_seconds = retry_after_for_queue();
        return o;
      }
      // ON CONFLICT: another API node inserted the same key since the check above.
      PgRows inserted = db->exec(
          "INSERT INTO jobs (id, state, idempotency_key, created_at, width, height, spp, "
          "samples_total, warnings_json, priority, scene_json, frame_first, frame_last) VALUES "
          "($1, 'queued', $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12) ON CONFLICT DO NOTHING "
          "RETURNING seq",
          {r.id, r.idempotency_key, std::to_string(r.created_at), param(r.width),
           param(r.height), param(r.spp), std::to_string(r.samples_total), r.warnings_json,
           param(r.priority), prepared.scene_json, param(r.frame_first), param(r.frame_last)});
      if (inserted.size() == 0) return existing_by_key(*db);
      r.seq = inserted.int_value(0, "seq");
      if (r.frame_count() > 0)
        db->exec(
            "INSERT INTO tasks (job_id, kind, params, priority, job_seq) SELECT $1, 'frame', "
            "jsonb_build_object('frame', f), $2, $3 FROM generate_series($4::int, $5::int) f",
            {r.id, param(r.priority), param(r.seq), param(r.frame_first), param(r.frame_last)});
      else if (!tiles.empty())
        db->exec(
            "INSERT INTO tasks (job_id, kind, params, priority, job_seq) SELECT $1, 'tile', p, "
            "$2, $3 FROM jsonb_array_elements($4::jsonb) WITH ORDINALITY AS t(p, n) ORDER BY n",
            {r.id, param(r.priority), param(r.seq), tile_params.dump()});
      else
        db->exec(
            "INSERT INTO tasks (job_id, kind, params, priority, job_seq) VALUES ($1, 'job', '{}', "
            "$2, $3)",
            {r.id, param(r.priority), param(r.seq)});
      // Delivered at commit: an idle worker wakes and claims it.
      db->exec(std::string("NOTIFY ") + kTaskChannel);
      return std::nullopt;
    });
    if (decided) return std::move(*decided);
  } catch (const StoreError& e) {
    std::fprintf(stderr, "penumbra serve: storing a new job failed: %s\n", e.what());
    out.kind = SubmitOutcome::Kind::kStoreFailed;
    out.retry_after_seconds = 2;
    return out;
  }
  if (prepared.folder) prepared.folder->commit();
  metrics_.count_submitted();
  out.record = std::move(r);
  out.kind = SubmitOutcome::Kind::kAccepted;
  return out;
}

JobView FarmService::make_view(const PgRows& rows, int row, PgConnection& db) const {
  JobView v;
  v.record = job_from_row(rows, row);
  if (v.record.state == JobState::kRunning) {
    v.progress = progress_from_row(rows, row);
    if (!v.progress) v.progress = RenderProgress{};
    v.progress->samples_total = v.record.samples_total;
    v.stop_requested = rows.value(row, "cancel_requested") == "t";
  }
  if (v.record.state == JobState::kQueued) {
    // Jobs ahead of it in run order: higher priority, or the same and submitted earlier.
    PgRows ahead = db.exec(
        "SELECT count(*) AS n FROM jobs WHERE state = 'queued' AND (priority > $1::bigint OR "
        "(priority = $1::bigint AND seq < $2::bigint))",
        {param(v.record.priority), param(v.record.seq)});
    v.queue_position = std::size_t(ahead.int_value(0, "n"));
  }
  return v;
}

std::optional<JobView> FarmService::view(const std::string& id) const {
  auto db = pool_.acquire();
  PgRows rows = db->exec(
      std::string("SELECT ") + kJobColumns + " FROM jobs WHERE id = $1 AND state <> 'deleted'", {id});
  if (rows.size() == 0) return std::nullopt;
  return make_view(rows, 0, *db);
}

std::vector<JobView> FarmService::list(std::optional<JobState> state, int64_t before_seq,
                                       int limit) const {
  auto db = pool_.acquire();
  PgRows rows = db->exec(
      std::string("SELECT ") + kJobColumns +
          " FROM jobs WHERE state <> 'deleted' AND ($1::text IS NULL OR state = $1) AND "
          "($2::bigint = 0 OR seq < $2::bigint) ORDER BY seq DESC LIMIT $3::bigint",
      {state ? PgParam(to_string(*state)) : std::nullopt, param(before_seq), param(limit)});
  std::vector<JobView> out;
  for (int i = 0; i < rows.size(); ++i) out.push_back(make_view(rows, i, *db));
  return out;
}

std::vector<JobView> FarmService::list_queued(std::optional<RunKey> after, int limit) const {
  auto db = pool_.acquire();
  PgRows rows = db->exec(
      std::string("SELECT ") + kJobColumns +
          " FROM jobs WHERE state = 'queued' AND ($1::boolean IS NOT TRUE OR priority < "
          "$2::bigint OR (priority = $2::bigint AND seq > $3::bigint)) ORDER BY priority DESC, "
          "seq LIMIT $4::bigint",
      {after ? "true" : "false", param(after ? after->priority : 0), param(after ? after->seq : 0),
       param(limit)});
  std::vector<JobView> out;
  for (int i = 0; i < rows.size(); ++i) out.push_back(make_view(rows, i, *db));
  return out;
}

DeleteOutcome FarmService::cancel_or_delete(const std::string& id, std::chrono::milliseconds wait) {
  enum class Found { kNothing, kTombstone, kFinished, kQueued, kRunning } found = Found::kNothing;
  {
    auto db = pool_.acquire();
    db->transaction([&] {
      PgRows rows = db->exec("SELECT state FROM jobs WHERE id = $1 FOR UPDATE", {id});
      if (rows.size() == 0) return;
      const auto state = job_state_from_string(rows.value(0, "state"));
      const std::string now = std::to_string(unix_now());
      if (state == JobState::kDeleted) {
        found = Found::kTombstone;
      } else if (state && is_finished(*state)) {
        // A tombstone, as one node keeps: a repeated DELETE still answers 204; the key is freed.
        found = Found::kFinished;
        db->exec(
            "UPDATE jobs SET state = 'deleted', finished_at = $2, idempotency_key = '', "
            "stats_json = '', error_json = '', warnings_json = '', scene_json = NULL, "
            "result_token = '' WHERE id = $1",
            {id, now});
      } else if (state == JobState::kQueued) {
        found = Found::kQueued;
        db->exec("UPDATE jobs SET state = 'cancelled', finished_at = $2 WHERE id = $1", {id, now});
        db->exec("UPDATE tasks SET state = 'cancelled' WHERE job_id = $1 AND state = 'queued'",
                 {id});
      } else {
        // The workers see it at their next heartbeat and stop; tasks not yet claimed never run.
        found = Found::kRunning;
        db->exec("UPDATE jobs SET cancel_requested = true WHERE id = $1", {id});
        db->exec("UPDATE tasks SET state = 'cancelled' WHERE job_id = $1 AND state = 'queued'",
                 {id});
        // No task under way (a split job between its last tile and its merge): nobody else
        // will end it.
        if (db->exec("SELECT 1 FROM tasks WHERE job_id = $1 AND state = 'running'", {id}).size() ==
            0) {
          found = Found::kQueued;
          db->exec(
              "UPDATE jobs SET state = 'cancelled', finished_at = $2, progress_json = '' WHERE "
              "id = $1",
              {id, now});
        }
      }
    });
  }
  switch (found) {
    case Found::kNothing:
      return DeleteOutcome::kNotFound;
    case Found::kTombstone:
      return DeleteOutcome::kDeleted;
    case Found::kFinished:
      remove_job_files(config_.data_dir, id);
      if (assets_) assets_->remove_job_folder(id);
      return DeleteOutcome::kDeleted;
    case Found::kQueued:
      if (assets_) assets_->remove_job_folder(id);
      metrics_.observe_render("cancelled", 0, 0);
      return DeleteOutcome::kCancelled;
    case Found::kRunning:
      break;
  }
  const auto done = wait_finished(id, std::chrono::steady_clock::now() + wait);
  return done && done->state != JobState::kRunning ? DeleteOutcome::kCancelled
                                                   : DeleteOutcome::kCancelling;
}

std::string farm_preview_path(const std::string& data_dir, const std::string& job_id) {
  return (std::filesystem::path(data_dir) / "previews" / (job_id + ".exr")).string();
}

std::shared_ptr<const Image> FarmService::preview(const std::string& id) const {
  if (!is_valid_job_id(id)) return nullptr;
  const std::string path = farm_preview_path(config_.data_dir, id);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return tiles_preview(id);
  try {
    // Written whole (temporary name, rename) by the worker: a reader sees one image or none.
    return std::make_shared<const Image>(read_image_file(path));
  } catch (const std::exception&) {
    return nullptr;  // removed meanwhile (the task ended): as if there were none yet
  }
}

std::shared_ptr<const Image> FarmService::tiles_preview(const std::string& id) const {
  const auto tiles = tile_previews(config_.data_dir, id);
  if (tiles.empty()) return nullptr;
  int width = 0, height = 0;
  try {
    auto db = pool_.acquire();
    PgRows rows = db->exec("SELECT width, height FROM jobs WHERE id = $1", {id});
    if (rows.size() == 0) return nullptr;
    width = int(rows.int_value(0, "width"));
    height = int(rows.int_value(0, "height"));
  } catch (const StoreError&) {
    return nullptr;
  }
  // Tiles not started yet stay black; each tile's last preview is copied into its window.
  auto frame = std::make_shared<Image>(width, height);
  for (const auto& [w, path] : tiles) {
    if (!w.fits(width, height)) continue;
    Image part;
    try {
      part = read_image_file(path);
    } catch (const std::exception&) {
      continue;  // replaced or removed meanwhile
    }
    if (part.width != w.width() || part.height != w.height()) continue;
    for (int y = 0; y < w.height(); ++y)
      std::copy_n(part.rgb.begin() + std::size_t(y) * w.width() * 3, std::size_t(w.width()) * 3,
                  frame->rgb.begin() + (std::size_t(w.y0 + y) * width + w.x0) * 3);
  }
  return frame;
}

std::optional<StoredResult> FarmService::open_result(const std::string& id,
                                                     const std::string& format,
                                                     std::optional<int> frame) const {
  std::string token;
  {
    auto db = pool_.acquire();
    PgRows rows = db->exec(
        "SELECT state, result_token, frame_first, frame_last FROM jobs WHERE id = $1", {id});
    if (rows.size() == 0) return std::nullopt;
    const int64_t first = rows.int_value(0, "frame_first"), last = rows.int_value(0, "frame_last");
    if (last < first) {
      // A still: its one result, once the job succeeded.
      if (frame || rows.value(0, "state") != "succeeded") return std::nullopt;
      token = rows.value(0, "result_token");
    } else {
      // An animation: each frame's committed task names its files, as soon as it is done.
      const int64_t f = frame ? int64_t(*frame) : first;
      if (f < first || f > last || rows.value(0, "state") == "deleted") return std::nullopt;
      PgRows t = db->exec(
          "SELECT result_token FROM tasks WHERE job_id = $1 AND kind = 'frame' AND state = "
          "'done' AND params @> jsonb_build_object('frame', $2::int)",
          {id, std::to_string(f)});
      if (t.size() == 0) return std::nullopt;
      token = t.value(0, "result_token");
    }
  }
  if (token.empty()) return std::nullopt;
  // Only the committed attempt's files are ever served (farm_worker.cpp, the lease protocol).
  return results_.open(id + "." + token, format);
}

std::optional<JobRecord> FarmService::wait_finished(
    const std::string& id, std::chrono::steady_clock::time_point deadline) const {
  std::optional<JobRecord> last;
  while (true) {
    try {
      auto db = pool_.acquire();
      PgRows rows = db->exec(std::string("SELECT ") + kJobColumns + " FROM jobs WHERE id = $1", {id});
      if (rows.size() == 0) return std::nullopt;
      last = job_from_row(rows, 0);
      if (is_finished(last->state) || last->state == JobState::kDeleted) return last;
    } catch (const StoreError&) {
      // The database restarts: keep waiting until the deadline.
    }
    if (stopping_ || std::chrono::steady_clock::now() >= deadline) return last;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

bool FarmService::storage_ok() const {
  try {
    auto db = pool_.acquire();
    db->exec("SELECT 1");
  } catch (const StoreError&) {
    return false;
  }
  const auto available = available_bytes(config_.data_dir);
  return !available || *available >= config_.min_free_bytes;
}

Metrics::Gauges FarmService::gauges() const {
  Metrics::Gauges g;
  g.ready = !stopping_;
  g.queue_capacity = config_.max_queue;
  g.event_streams = events_.open_streams();
  try {
    auto db = pool_.acquire();
    PgRows states = db->exec("SELECT state, count(*) AS n FROM jobs GROUP BY state");
    for (int i = 0; i < states.size(); ++i) {
      const std::string s = states.value(i, "state");
      if (s == "deleted") continue;
      g.jobs_by_state[s] = states.int_value(i, "n");
      if (s == "running") g.running = states.int_value(i, "n");
      if (s == "queued") g.queue_depth = states.int_value(i, "n");
    }
    std::string text;
    text += "# HELP penumbra_farm_queue_depth Tasks waiting for a worker, by job priority.\n"
            "# TYPE penumbra_farm_queue_depth gauge\n";
    PgRows depth = db->exec(
        "SELECT priority, count(*) AS n FROM tasks WHERE state = 'queued' GROUP BY priority "
        "ORDER BY priority");
    for (int i = 0; i < depth.size(); ++i)
      text += "penumbra_farm_queue_depth{priority=\"" + depth.value(i, "priority") + "\"} " +
              depth.value(i, "n") + "\n";
    PgRows attempts = db->exec(
        "SELECT count(*) FILTER (WHERE outcome = 'lease_expired') AS expired, "
        "count(*) FILTER (WHERE outcome = 'lease_lost') AS lost, "
        "count(*) - count(DISTINCT task_id) AS retries FROM task_attempts");
    text += "# HELP penumbra_farm_lease_expiries_total Task leases that expired (worker lost).\n"
            "# TYPE penumbra_farm_lease_expiries_total counter\n"
            "penumbra_farm_lease_expiries_total " + attempts.value(0, "expired") + "\n";
    text += "# HELP penumbra_farm_retries_total Task attempts beyond each task's first.\n"
            "# TYPE penumbra_farm_retries_total counter\n"
            "penumbra_farm_retries_total " + attempts.value(0, "retries") + "\n";
    // Per worker: bounded by the workers that ever registered (rows are removed by operators;
    // docs/scale-out.md), not by jobs.
    PgRows workers = db->exec(
        "SELECT id, tasks_succeeded, tasks_failed FROM workers WHERE stopped_at IS NULL ORDER "
        "BY id");
    text += "# HELP penumbra_farm_worker_tasks_total Tasks a live worker finished, by outcome.\n"
            "# TYPE penumbra_farm_worker_tasks_total counter\n";
    for (int i = 0; i < workers.size(); ++i) {
      const std::string w = workers.value(i, "id");
      text += "penumbra_farm_worker_tasks_total{worker=\"" + w + "\",outcome=\"succeeded\"} " +
              workers.value(i, "tasks_succeeded") + "\n";
      text += "penumbra_farm_worker_tasks_total{worker=\"" + w + "\",outcome=\"failed\"} " +
              workers.value(i, "tasks_failed") + "\n";
    }
    g.extra_text = std::move(text);
  } catch (const StoreError&) {
    g.ready = false;
  }
  return g;
}

nlohmann::json FarmService::workers() const {
  auto db = pool_.acquire();
  PgRows rows = db->exec(
      "SELECT w.id, w.host, w.pid, w.slots, w.render_threads, "
      "extract(epoch FROM w.started_at) AS started_at, "
      "extract(epoch FROM w.heartbeat_at) AS heartbeat_at, "
      "extract(epoch FROM now() - w.heartbeat_at) AS heartbeat_age, "
      "w.tasks_succeeded, w.tasks_failed, "
      "coalesce((SELECT json_agg(json_build_object('task', t.id, 'kind', t.kind, 'job', t.job_id, "
      "'attempt', t.attempts, 'window', t.params->'window', 'frame', t.params->'frame', "
      "'lease_expires', extract(epoch FROM t.lease_expires))) FROM tasks t "
      "WHERE t.state = 'running' AND t.lease_owner = w.id), '[]') AS current "
      "FROM workers w WHERE w.stopped_at IS NULL ORDER BY w.id");
  nlohmann::json all = nlohmann::json::array();
  for (int i = 0; i < rows.size(); ++i) {
    const double age = rows.double_value(i, "heartbeat_age");
    all.push_back({{"id", rows.value(i, "id")},
                   {"host", rows.value(i, "host")},
                   {"pid", rows.int_value(i, "pid")},
                   {"slots", rows.int_value(i, "slots")},
                   {"render_threads", rows.int_value(i, "render_threads")},
                   {"started_at", rows.double_value(i, "started_at")},
                   {"heartbeat_at", rows.double_value(i, "heartbeat_at")},
                   // A worker whose heartbeat is older than a lease is presumed lost.
                   {"alive", age < config_.lease_seconds},
                   {"tasks_succeeded", rows.int_value(i, "tasks_succeeded")},
                   {"tasks_failed", rows.int_value(i, "tasks_failed")},
                   {"current_tasks", nlohmann::json::parse(rows.value(i, "current"))}});
  }
  return all;
}

void FarmService::event_loop() {
  // Job changes since `version`, turned into the stream's events: a state change is an event,
  // a running job's new progress a progress sample. Woken by NOTIFY, polled every second anyway.
  std::unordered_map<std::string, JobState> known;
  int64_t version = -1;
  std::unique_ptr<PgConnection> db;
  while (!stopping_) {
    try {
      if (!db) {
        db = std::make_unique<PgConnection>(pool_.url());
        db->listen(kJobChannel);
      }
      if (version < 0) {
        PgRows v = db->exec("SELECT coalesce(max(version), 0) AS v FROM jobs");
        version = v.int_value(0, "v");
      }
      PgRows rows = db->exec(std::string("SELECT ") + kJobColumns +
                                 " FROM jobs WHERE version > $1 ORDER BY version LIMIT 1000",
                             {std::to_string(version)});
      for (int i = 0; i < rows.size(); ++i) {
        version = std::max<int64_t>(version, rows.int_value(i, "version"));
        const JobRecord r = job_from_row(rows, i);
        const auto it = known.find(r.id);
        const bool changed = it == known.end() || it->second != r.state;
        if (changed) {
          std::optional<std::size_t> position;
          if (r.state == JobState::kQueued) position = make_view(rows, i, *db).queue_position;
          events_.record_change(r, position);
        } else if (r.state == JobState::kRunning) {
          if (auto p = progress_from_row(rows, i)) events_.sample_progress(r, *p);
        }
        if (is_finished(r.state) || r.state == JobState::kDeleted)
          known.erase(r.id);
        else
          known[r.id] = r.state;
      }
      if (rows.size() < 1000) db->wait_notification(1.0);
    } catch (const StoreError& e) {
      std::fprintf(stderr, "penumbra serve: job events: %s\n", e.what());
      db.reset();
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
}

}  // namespace penumbra::server
