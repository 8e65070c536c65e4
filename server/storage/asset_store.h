#pragma once
// The content-addressed asset store of the HTTP service (issue 12), after Flamenco's "Shaman":
// each file is kept once under its SHA-256 in DATA/assets/sha256/<64 hex>, so a client uploads
// a mesh or texture once however many jobs use it.
//
// Durability: an upload streams into DATA/assets/tmp/ while it is hashed, is fsync'd, and only
// then renamed to its hash (and the folder fsync'd): a half-written or interrupted upload never
// becomes visible under a hash, and an acknowledged one survives kill -9. Leftovers in tmp/ are
// removed at start, and the index (size, last use) is rebuilt from the files.
//
// Jobs: a job's manifest is materialised as DATA/assets/jobs/<job id>/<name> hard links to the
// stored files; that folder is the only one its scene may read (api::AssetFolder). A store file
// whose link count is above one is therefore in some job's folder: eviction (oldest last use
// first, to keep the store under --max-asset-store) never takes such a file. Folders of jobs that
// are no longer queued or running are removed (the service's liveness callback says which).
#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "api/job_submission.h"
#include "server/storage/sha256.h"

namespace penumbra::server {

struct AssetStoreLimits {
  std::uint64_t max_asset_bytes = std::uint64_t(256) << 20;  // one file
  std::uint64_t max_store_bytes = std::uint64_t(10) << 30;   // all stored files
};

enum class PutStatus {
  kStored,         // new file, durable
  kAlreadyStored,  // the hash was known (another upload won, or it was there already)
  kMismatch,       // the bytes hash to something else (422)
  kTooLarge,       // more bytes than --max-asset-size (413)
  kNoRoom,         // the store is full of assets jobs still use (507)
};

struct PutResult {
  PutStatus status = PutStatus::kStored;
  std::string actual_hash;  // kMismatch
  std::uint64_t size = 0;
};

// One upload in progress: bytes go to a temporary file and through the hash.
class AssetUpload {
 public:
  AssetUpload(std::string expected_hash, std::string tmp_path, std::uint64_t max_bytes);
  ~AssetUpload();  // removes the temporary file unless it was moved into the store
  AssetUpload(const AssetUpload&) = delete;
  AssetUpload& operator=(const AssetUpload&) = delete;
  // False once the upload is over the size limit (then the rest is not written).
  bool write(const char* data, std::size_t size);
  bool too_large() const { return too_large_; }
  std::uint64_t size() const { return size_; }
  const std::string& expected_hash() const { return expected_; }

 private:
  friend class AssetStore;
  std::string expected_;
  std::string tmp_path_;
  std::uint64_t max_bytes_;
  int fd_ = -1;
  Sha256 hash_;
  std::uint64_t size_ = 0;
  bool too_large_ = false;
  bool moved_ = false;
};

struct JobLinkResult {
  std::vector<std::string> missing;  // manifest names whose hash the store does not hold
  std::uint64_t total_bytes = 0;
  bool ok() const { return missing.empty(); }
};

class AssetStore {
 public:
  // `shared`: the folder is a farm's volume that other nodes write too; interrupted uploads in
  // its tmp/ may be theirs, under way, and are left alone.
  AssetStore(const std::string& data_dir, AssetStoreLimits limits, bool shared = false);

  // Which jobs still need their folder (queued or running); folders of others are removed by
  // sweep_job_folders() and before anything is evicted. Unset: every folder is kept.
  void set_job_liveness(std::function<bool(const std::string& job_id)> is_live);

  const AssetStoreLimits& limits() const { return limits_; }
  bool contains(const std::string& hash) const;
  std::optional<std::uint64_t> size_of(const std::string& hash) const;
  std::vector<std::string> missing(const std::vector<std::string>& hashes) const;
  std::uint64_t stored_bytes() const;
  std::size_t stored_count() const;

  // The stored file, open for reading (it stays readable if evicted meanwhile), and its size.
  std::optional<std::pair<std::shared_ptr<std::ifstream>, std::uint64_t>> open(
      const std::string& hash) const;

  std::unique_ptr<AssetUpload> begin_upload(const std::string& expected_hash);
  // Stores bytes already in memory (the one-shot job forms); same checks as an upload.
  PutResult put_bytes(std::string_view bytes, std::string* hash_out);
  // Links a stored file into a fresh folder under tmp/ as `name` and returns its path, to read
  // it where a file name is needed (the glTF scene builder); unstage removes that folder.
  std::string stage(const std::string& hash, const std::string& name);
  void unstage(const std::string& staged_path);

  // Checks the hash, makes room (evicting unreferenced assets, oldest use first) and moves the
  // file into place durably. Throws std::runtime_error on an I/O failure.
  PutResult finish_upload(std::unique_ptr<AssetUpload> upload);

  // Creates the job's folder of hard links (durably), pending until commit_job_folder (so a
  // sweep does not take a folder whose job is not yet in the table). Nothing is left behind
  // when some names are missing. Throws std::runtime_error on an I/O failure.
  JobLinkResult link_job_folder(const std::string& job_id,
                                const std::vector<api::ManifestEntry>& manifest);
  void commit_job_folder(const std::string& job_id);
  void remove_job_folder(const std::string& job_id);
  // The folder a job's scene reads, whether or not it exists.
  std::string job_folder(const std::string& job_id) const;
  // Removes the folders of jobs that are not live (and not pending).
  void sweep_job_folders();

 private:
  struct Entry {
    std::uint64_t size = 0;
    std::int64_t last_used_ns = 0;
  };
  std::string asset_path(const std::string& hash) const;
  void sweep_locked();
  // Evicts unreferenced assets, oldest first, until `incoming` more bytes fit; false if they
  // cannot.
  bool make_room_locked(std::uint64_t incoming);
  // Shared store: an asset another node stored since this one indexed the folder is taken into
  // the index when it is first asked for. The index, not the file, is what is asked here.
  void adopt_locked(const std::string& hash) const;

  const std::string root_;
  const AssetStoreLimits limits_;
  mutable std::mutex mutex_;
  const bool shared_;
  // Mutable for adopt_locked (a lookup of a shared store learns what other nodes stored).
  mutable std::map<std::string, Entry> index_;
  mutable std::uint64_t stored_bytes_ = 0;
  std::set<std::string> pending_jobs_;
  std::function<bool(const std::string&)> is_live_;
};

// DATA/assets/jobs/<id>: where the render worker finds a job's files.
std::string job_asset_folder(const std::string& data_dir, const std::string& job_id);

}  // namespace penumbra::server
