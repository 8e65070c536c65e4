#include "server/farm/farm_schema.h"

#include <string>
#include <vector>

namespace penumbra::server {
namespace {

// Arbitrary, fixed: the advisory lock key of schema changes (pg_advisory_xact_lock).
constexpr const char* kMigrationLockKey = "7305196184402219";

// Migration N is kMigrations[N - 1]. Never edit one that has shipped: add the next.
const std::vector<const char*> kMigrations = {
    // 1: jobs, tasks (a job's units of work: "job" = the whole frame today; "tile" and "frame"
    // later, told apart by kind and params), the attempt log, workers and counters.
    R"sql(
CREATE TABLE jobs (
  id text PRIMARY KEY,
  seq bigint GENERATED ALWAYS AS IDENTITY UNIQUE,
  state text NOT NULL,
  idempotency_key text NOT NULL DEFAULT '',
  created_at double precision NOT NULL,
  started_at double precision NOT NULL DEFAULT 0,
  finished_at double precision NOT NULL DEFAULT 0,
  attempts integer NOT NULL DEFAULT 0,
  width integer NOT NULL, height integer NOT NULL, spp integer NOT NULL,
  samples_total bigint NOT NULL,
  stats_json text NOT NULL DEFAULT '',
  error_json text NOT NULL DEFAULT '',
  warnings_json text NOT NULL DEFAULT '',
  priority integer NOT NULL DEFAULT 0,
  scene_json text,
  -- The lease token of the attempt whose result was committed: results/<id>.<token>.<format>.
  result_token text NOT NULL DEFAULT '',
  cancel_requested boolean NOT NULL DEFAULT false,
  -- {"fraction":..,"eta_seconds":..,"samples_done":..} written at each heartbeat while running.
  progress_json text NOT NULL DEFAULT '',
  -- Bumped on every change (trigger below): the API nodes' event streams read changes after N.
  version bigint NOT NULL DEFAULT 0
);
CREATE UNIQUE INDEX jobs_idempotency_key ON jobs (idempotency_key)
  WHERE idempotency_key <> '' AND state <> 'deleted';
CREATE INDEX jobs_state_seq ON jobs (state, seq);
CREATE INDEX jobs_version ON jobs (version);
CREATE SEQUENCE job_versions;
CREATE FUNCTION jobs_bump_version() RETURNS trigger AS $$
BEGIN
  NEW.version := nextval('job_versions');
  RETURN NEW;
END $$ LANGUAGE plpgsql;
CREATE TRIGGER jobs_version BEFORE INSERT OR UPDATE ON jobs
  FOR EACH ROW EXECUTE FUNCTION jobs_bump_version();

CREATE TABLE tasks (
  id bigint GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
  job_id text NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  kind text NOT NULL DEFAULT 'job',
  params jsonb NOT NULL DEFAULT '{}',
  state text NOT NULL DEFAULT 'queued',  -- queued, running, done, failed, cancelled
  priority integer NOT NULL,
  job_seq bigint NOT NULL,
  attempts integer NOT NULL DEFAULT 0,
  lease_token text,
  lease_owner text,
  lease_expires timestamptz,
  last_error text NOT NULL DEFAULT ''
);
-- Run order, as one node's queue: higher priority first, then submission order.
CREATE INDEX tasks_runnable ON tasks (priority DESC, job_seq, id) WHERE state = 'queued';
CREATE INDEX tasks_leased ON tasks (lease_expires) WHERE state = 'running';
CREATE INDEX tasks_job ON tasks (job_id);

-- One row per claim: how often each task rendered, by whom, and how each attempt ended.
CREATE TABLE task_attempts (
  id bigint GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
  task_id bigint NOT NULL,
  job_id text NOT NULL,
  worker text NOT NULL,
  lease_token text NOT NULL,
  started_at timestamptz NOT NULL DEFAULT now(),
  ended_at timestamptz,
  outcome text NOT NULL DEFAULT 'running'  -- succeeded, failed, cancelled, lease_expired, lease_lost
);
CREATE INDEX task_attempts_job ON task_attempts (job_id);

CREATE TABLE workers (
  id text PRIMARY KEY,
  host text NOT NULL,
  pid integer NOT NULL,
  slots integer NOT NULL,
  render_threads integer NOT NULL,
  started_at timestamptz NOT NULL DEFAULT now(),
  heartbeat_at timestamptz NOT NULL DEFAULT now(),
  stopped_at timestamptz,
  tasks_succeeded bigint NOT NULL DEFAULT 0,
  tasks_failed bigint NOT NULL DEFAULT 0
);
)sql",
    // 2: jobs of several tasks (docs/scale-out.md, "Tasks"). A frame split into windows: tasks of
    // kind "tile" (params {"window": [x0, y0, x1, y1]}) and, once the last tile commits, one
    // "merge"; an animation: one task of kind "frame" per frame (params {"frame": i}). Each task
    // keeps the lease token of its committed attempt (its files' names), its last progress and
    // its render statistics; a job counts its finished frames.
    R"sql(
ALTER TABLE jobs ADD COLUMN frame_first integer NOT NULL DEFAULT 0,
  ADD COLUMN frame_last integer NOT NULL DEFAULT -1,
  ADD COLUMN frames_done integer NOT NULL DEFAULT 0;
ALTER TABLE tasks ADD COLUMN result_token text NOT NULL DEFAULT '',
  ADD COLUMN progress_json text NOT NULL DEFAULT '',
  ADD COLUMN stats_json text NOT NULL DEFAULT '';
CREATE INDEX tasks_job_kind ON tasks (job_id, kind, state);
)sql",
};

}  // namespace

int farm_schema_version() { return int(kMigrations.size()); }

int migrate_farm_schema(PgConnection& db) {
  return db.transaction([&] {
    // Held to the end of this transaction: two nodes starting together apply each step once.
    db.exec(std::string("SELECT pg_advisory_xact_lock(") + kMigrationLockKey + ")");
    db.exec(
        "CREATE TABLE IF NOT EXISTS schema_migrations (version integer PRIMARY KEY, "
        "applied_at timestamptz NOT NULL DEFAULT now())");
    PgRows current = db.exec("SELECT coalesce(max(version), 0) AS v FROM schema_migrations");
    const int at = int(current.int_value(0, "v"));
    if (at > farm_schema_version())
      throw StoreError("the database's schema is at version " + std::to_string(at) +
                       ", newer than this build knows (" + std::to_string(farm_schema_version()) +
                       "): upgrade this node");
    for (int v = at + 1; v <= farm_schema_version(); ++v) {
      db.exec(kMigrations[std::size_t(v - 1)]);
      db.exec("INSERT INTO schema_migrations (version) VALUES ($1)", {std::to_string(v)});
    }
    return farm_schema_version();
  });
}

}  // namespace penumbra::server
