#pragma once
// A render worker of the farm: claims tasks from PostgreSQL (FOR UPDATE SKIP LOCKED, in run
// order), holds a lease it renews at every heartbeat, renders, and commits the result only
// while it still holds the lease (docs/scale-out.md, "The lease protocol"). Idle, it sleeps on
// LISTEN until a task is announced (a slow poll covers a missed notification). It also returns
// the tasks of lost workers (expired leases) to the queue.
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/farm/farm_tasks.h"
#include "server/farm/pg_connection.h"
#include "server/farm/scene_cache.h"
#include "server/jobs/job_runtime.h"
#include "server/jobs/render_task.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/storage/file_result_store.h"

namespace penumbra::server {

class FarmWorker {
 public:
  FarmWorker(const ServerConfig& config, FileResultStore& results, Metrics& metrics);
  ~FarmWorker();
  // Registers the worker and starts --workers slots, each rendering one task at a time.
  void start();
  // Stops claiming; running renders stop and their tasks go back to the queue (the attempt does
  // not count).
  void begin_shutdown();
  void join();
  const std::string& id() const { return id_; }

 private:
  struct Claim {
    int64_t task = 0;
    std::string job, token, scene;
    std::string kind = "job";  // job, tile, frame, merge (farm_tasks.h)
    TaskPiece piece;           // a tile's window, a frame's number
    int width = 0, height = 0;  // the job's frame
    int attempt = 0;
  };
  // The scene a slot keeps from its last task for its next (scene_cache.h).
  struct KeptScene {
    std::string key;
    std::shared_ptr<const PreparedScene> scene;
  };
  void slot_loop();
  // Returns the tasks of expired leases to the queue; the number returned.
  int reap_expired(PgConnection& db);
  // True when queued tasks of live jobs exist that the last claim passed over (locked rows).
  bool claimable_tasks_locked(PgConnection& db);
  std::optional<Claim> claim(PgConnection& db);
  void run(PgConnection& db, const Claim& claim, KeptScene& kept);
  // A tile's or frame's render, from the job's scene as this worker prepared it once.
  RenderOutcome render_piece(const Claim& claim, const RenderJobOptions& options,
                             JobRuntime& runtime, KeptScene& kept);
  // A split frame's last step: the committed tiles merged (bit for bit the single-machine
  // image), denoised if the job asks, stored as the job's result; RenderOutcome as a render's.
  RenderOutcome merge_tiles(PgConnection& db, const Claim& claim, JobRuntime& runtime);
  // The progress of a job of several tasks, from every task's last progress (tasks.progress_json)
  // with this task's `mine`: samples over the whole job, elapsed since its first task started.
  std::string job_progress_json(PgConnection& db, const Claim& claim, const RenderProgress& mine);
  // The heartbeat of one claim: renews the lease, writes progress, sees a cancellation.
  void heartbeat_loop(const Claim& claim, JobRuntime& runtime, std::atomic<bool>& done,
                      std::atomic<bool>& lease_lost);
  // Runs `commit` (one transaction) again while the database is unreachable, until the lease
  // would have expired; false when it could not be committed.
  bool commit_with_retry(PgConnection& db, const std::function<void()>& commit);

  const ServerConfig config_;
  FileResultStore& results_;
  Metrics& metrics_;
  std::string host_, id_;
  std::atomic<bool> stopping_{false};
  std::mutex runtimes_mutex_;
  std::vector<std::shared_ptr<JobRuntime>> runtimes_;
  std::vector<std::thread> slots_;
  SceneCache scenes_;
};

}  // namespace penumbra::server
