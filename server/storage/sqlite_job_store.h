#pragma once
// JobStore on one SQLite file (WAL, synchronous=FULL): apply() returns once its transaction is
// on disk, so a job answered 202 survives kill -9 and power loss. Result images live elsewhere
// (ResultStore); the database keeps no pixels.
#include <mutex>
#include <string>

#include "server/storage/job_store.h"

struct sqlite3;

namespace penumbra::server {

class SqliteJobStore final : public JobStore {
 public:
  // Opens (creating if needed) the database file; throws StoreError. The schema is the one
  // earlier versions wrote, so an existing data directory opens unchanged.
  explicit SqliteJobStore(const std::string& path);
  ~SqliteJobStore() override;
  SqliteJobStore(const SqliteJobStore&) = delete;
  SqliteJobStore& operator=(const SqliteJobStore&) = delete;

  StoredJobs load() override;
  std::optional<std::string> scene(const std::string& id) override;
  void apply(const std::vector<JobChange>& changes) override;

 private:
  void exec(const char* sql);
  void apply_one(const JobChange& change);
  sqlite3* db_ = nullptr;
  // One connection, used by one thread at a time. Only the store writer thread commits; the
  // other callers (startup, a worker reading its scene, a submission comparing scenes) may
  // wait for a commit here, the status path never comes here.
  std::mutex mutex_;
};

}  // namespace penumbra::server
