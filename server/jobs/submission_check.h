#pragma once
// The part of a submission every backend does alike, before anything is stored: the job's
// options split off, the envelope parsed, the manifest's files linked into the job's folder, the
// scene validated, and the new job's record made (id, size, priority, webhook; no seq yet).
// JobService (one node) and FarmService (PostgreSQL) then check capacity and commit it their way.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "api/job_submission.h"
#include "server/jobs/job_backend.h"
#include "server/server_config.h"
#include "server/storage/asset_store.h"

namespace penumbra::server {

// Removes the new job's asset folder on every way out but acceptance (commit()).
class JobFolderGuard {
 public:
  JobFolderGuard(AssetStore* assets, std::string id) : assets_(assets), id_(std::move(id)) {}
  ~JobFolderGuard();
  JobFolderGuard(const JobFolderGuard&) = delete;
  JobFolderGuard& operator=(const JobFolderGuard&) = delete;
  // The job is accepted: its folder stays.
  void commit();

 private:
  AssetStore* assets_;
  std::string id_;
};

struct PreparedSubmission {
  std::optional<SubmitOutcome> refusal;  // set: the answer (400/422/503), nothing to store
  JobRecord record;                      // state queued, seq 0 (the backend numbers it)
  std::string scene_json;                // what the worker renders (scene or envelope, no options)
  std::vector<api::Diagnostic> warnings;
  std::uint64_t worst_case_bytes = 0;    // the job's result images at most
  std::unique_ptr<JobFolderGuard> folder;  // null when the job names no files
};

// The serve flags that bound a job's manifest.
api::ManifestLimits manifest_limits(const ServerConfig& config);

PreparedSubmission prepare_submission(const ServerConfig& config, AssetStore* assets,
                                      std::string_view body, const std::string& idempotency_key);

// The job's new id: 24 lowercase hex digits from /dev/urandom (unguessable).
std::string new_job_id();

}  // namespace penumbra::server
