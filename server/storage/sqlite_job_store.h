#pragma once
// JobStore on one SQLite file (WAL, synchronous=FULL): apply() returns once its transaction is
// on disk, so a job answered 202 survives kill -9 and power loss. Result images live elsewhere
// (ResultStore); the database keeps no pixels, and no scenes either: each scene is a file
// scenes/<id>.json beside the database (written and fsync'd before the row that names it is
// committed, removed with the tombstone or the erase), so a 12 MB scene does not stay in the
// database and its WAL (issue 15: 138 MB after 11 jobs). Rows of older versions keep their scene
// in the column and are read from there.
#include <mutex>
#include <string>
#include <vector>

#include "server/storage/job_store.h"

struct sqlite3;

namespace penumbra::server {

class SqliteJobStore final : public JobStore {
 public:
  // Opens (creating if needed) the database file; throws StoreError. The schema is the one
  // earlier versions wrote, so an existing data directory opens unchanged.
  explicit SqliteJobStore(const std::string& path);
  // The folder of the scene files (scenes/ beside the database).
  const std::string& scenes_dir() const { return scenes_dir_; }
  ~SqliteJobStore() override;
  SqliteJobStore(const SqliteJobStore&) = delete;
  SqliteJobStore& operator=(const SqliteJobStore&) = delete;

  StoredJobs load() override;
  std::optional<std::string> scene(const std::string& id) override;
  void apply(const std::vector<JobChange>& changes) override;

 private:
  void exec(const char* sql);
  // An additive migration: ALTER TABLE jobs ADD COLUMN name decl, unless it is there.
  void add_column_if_missing(const std::string& name, const std::string& decl);
  // Files to remove once the transaction that drops their rows has committed.
  void apply_one(const JobChange& change, std::vector<std::string>& remove_after_commit);
  std::string scene_path(const std::string& id) const;
  void write_scene(const std::string& id, const std::string& scene_json) const;
  // Scene files with no row (a crash between the file and the commit): removed at load().
  void remove_orphan_scenes(const std::vector<JobRecord>& records) const;
  sqlite3* db_ = nullptr;
  std::string scenes_dir_;
  // One connection, used by one thread at a time. Only the store writer thread commits; the
  // other callers (startup, a worker reading its scene, a submission comparing scenes) may
  // wait for a commit here, the status path never comes here.
  std::mutex mutex_;
};

}  // namespace penumbra::server
