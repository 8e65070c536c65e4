#pragma once
// Durable job records in SQLite (WAL, synchronous=FULL): a job answered 202 has been committed
// to disk. Result images live beside the database (see ResultFiles); the store keeps no pixels.
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "server/job_record.h"

struct sqlite3;

namespace penumbra::server {

struct StoreError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class JobStore {
 public:
  // Opens (creating if needed) the database file; throws StoreError.
  explicit JobStore(const std::string& path);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  struct InsertResult {
    JobRecord record;
    bool created = false;        // false: the idempotency key was already used
    bool same_scene = true;      // when !created: whether the stored scene equals this one
  };
  // Inserts a queued job, or, when `record.idempotency_key` is already used, returns that job.
  InsertResult insert(const JobRecord& record, const std::string& scene_json);

  struct KeyMatch {
    JobRecord record;
    bool same_scene = false;
  };
  // The job submitted with this idempotency key, and whether its scene is byte-identical.
  std::optional<KeyMatch> find_by_idempotency_key(const std::string& key, const std::string& scene_json);
  std::optional<JobRecord> get(const std::string& id);
  std::optional<std::string> scene(const std::string& id);
  // Newest first; jobs with seq < before_seq (0 = from the newest); state filter optional.
  std::vector<JobRecord> list(std::optional<JobState> state, int64_t before_seq, int limit);

  void mark_running(const std::string& id, double now);
  void mark_finished(const std::string& id, JobState state, double now, const std::string& stats_json,
                     const std::string& error_json);
  // Back to the queue (shutdown interrupted it): the attempt does not count.
  void requeue(const std::string& id);
  // A finished job's record becomes a tombstone so a repeated DELETE still answers 204.
  void mark_deleted(const std::string& id, double now);

  // At startup: running jobs were interrupted (crash or kill -9) and go back to the queue.
  // Returns every queued job in submission order.
  std::vector<JobRecord> recover();
  // Finished jobs older than `finished_before` (and old tombstones): deleted, ids returned.
  std::vector<std::string> expire(double finished_before);
  std::map<JobState, int64_t> count_by_state();

 private:
  void exec(const char* sql);
  sqlite3* db_ = nullptr;
  std::mutex mutex_;  // one connection, serialised: every statement here takes microseconds
};

}  // namespace penumbra::server
