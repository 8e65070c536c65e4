#pragma once
// Where job records persist: the interface every backend implements (SQLite in
// sqlite_job_store.h; a PostgreSQL one adds its own file pair and nothing here changes).
//
// The job service keeps the authoritative state in memory (jobs/job_table.h) and sends every
// change here, in the order it made them, from one writer thread (jobs/store_writer.h), so a
// status poll never waits on a commit. The store is read at startup (load) and for a job's scene.
// Nothing in this interface names SQL, a connection or a transaction mode.
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "server/storage/job_record.h"
#include "server/storage/store_error.h"

namespace penumbra::server {

// A new job and the scene it renders. The scene is kept apart from the record: it can be
// megabytes and is read once, by the worker that renders it.
struct InsertJob {
  JobRecord record;
  std::string scene_json;
};
// A job's record takes these values (every field but id, seq and created_at; the scene is kept).
// A record in state kDeleted is a tombstone: the store drops its scene and frees its
// idempotency key (record.idempotency_key is then "").
struct UpdateJob {
  JobRecord record;
};
// The job is gone for good (expired).
struct EraseJob {
  std::string id;
};
using JobChange = std::variant<InsertJob, UpdateJob, EraseJob>;

// "insert <id>", "update <id> <state>", "erase <id>": for log lines about a change.
std::string describe(const JobChange& change);

struct StoredJobs {
  std::vector<JobRecord> records;  // every job, tombstones included, in no particular order
  // The highest seq ever stored, erased jobs included: new jobs get higher ones, so an old
  // page token never names a newer job.
  int64_t last_seq = 0;
};

class JobStore {
 public:
  virtual ~JobStore() = default;

  // Everything stored; read once at startup. Throws StoreError.
  virtual StoredJobs load() = 0;
  // A job's scene; nullopt when the job is unknown or a tombstone. Throws StoreError.
  virtual std::optional<std::string> scene(const std::string& id) = 0;
  // Applies the changes in order as one atomic step that is durable when it returns: all of
  // them survive a kill -9 or a power cut from then on. Throws StoreError, and then none of
  // them was applied.
  virtual void apply(const std::vector<JobChange>& changes) = 0;
};

}  // namespace penumbra::server
