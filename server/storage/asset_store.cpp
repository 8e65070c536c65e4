#include "server/storage/asset_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>

#include "server/storage/job_record.h"
#include "server/storage/sha256.h"

namespace penumbra::server {
namespace fs = std::filesystem;

namespace {

void fsync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) throw std::runtime_error("cannot fsync " + path + ": " + std::strerror(errno));
}

void fsync_dir(const std::string& dir) { fsync_path(dir, O_RDONLY | O_DIRECTORY); }

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::int64_t mtime_ns(const struct stat& st) {
  return std::int64_t(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
}

std::string random_name() {
  static thread_local std::random_device rd;
  static const char* kHex = "0123456789abcdef";
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const std::uint32_t v = rd();
    for (int k = 0; k < 8; ++k) s += kHex[(v >> (4 * k)) & 15];
  }
  return s;
}

}  // namespace

std::string job_asset_folder(const std::string& data_dir, const std::string& job_id) {
  return (fs::path(data_dir) / "assets" / "jobs" / job_id).string();
}

AssetUpload::AssetUpload(std::string expected_hash, std::string tmp_path, std::uint64_t max_bytes)
    : expected_(std::move(expected_hash)), tmp_path_(std::move(tmp_path)), max_bytes_(max_bytes) {
  fd_ = ::open(tmp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw std::runtime_error("cannot create " + tmp_path_ + ": " + std::strerror(errno));
}

AssetUpload::~AssetUpload() {
  if (fd_ >= 0) ::close(fd_);
  if (!moved_) ::unlink(tmp_path_.c_str());
}

bool AssetUpload::write(const char* data, std::size_t size) {
  if (too_large_) return false;
  if (size_ + size > max_bytes_) {
    too_large_ = true;
    return false;
  }
  hash_.update(data, size);
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("cannot write " + tmp_path_ + ": " + std::strerror(errno));
    done += std::size_t(n);
  }
  size_ += size;
  return true;
}

AssetStore::AssetStore(const std::string& data_dir, AssetStoreLimits limits, bool shared)
    : root_((fs::path(data_dir) / "assets").string()), limits_(limits), shared_(shared) {
  const fs::path root(root_);
  fs::create_directories(root / "sha256");
  fs::create_directories(root / "tmp");
  fs::create_directories(root / "jobs");
  // Interrupted uploads: never visible under a hash, gone at start.
  if (!shared)
    for (const auto& e : fs::directory_iterator(root / "tmp")) fs::remove_all(e.path());
  for (const auto& e : fs::directory_iterator(root / "sha256")) {
    const std::string name = e.path().filename().string();
    struct stat st {};
    if (!api::is_sha256_hex(name) || ::lstat(e.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
      fs::remove_all(e.path());  // not ours (a stray file, a symbolic link): never served
      continue;
    }
    index_[name] = Entry{std::uint64_t(st.st_size), mtime_ns(st)};
    stored_bytes_ += std::uint64_t(st.st_size);
  }
  // Job folders whose name is not a job id cannot belong to a job.
  for (const auto& e : fs::directory_iterator(root / "jobs"))
    if (!is_valid_job_id(e.path().filename().string())) fs::remove_all(e.path());
}

void AssetStore::set_job_liveness(std::function<bool(const std::string&)> is_live) {
  std::lock_guard lock(mutex_);
  is_live_ = std::move(is_live);
}

std::string AssetStore::asset_path(const std::string& hash) const {
  return root_ + "/sha256/" + hash;
}

std::string AssetStore::job_folder(const std::string& job_id) const {
  return root_ + "/jobs/" + job_id;
}

void AssetStore::adopt_locked(const std::string& hash) const {
  if (!shared_ || index_.count(hash) || !api::is_sha256_hex(hash)) return;
  struct stat st {};
  // Files appear under their hash only whole (renamed from tmp/ after fsync, put()).
  if (::lstat(asset_path(hash).c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
  index_[hash] = Entry{std::uint64_t(st.st_size), mtime_ns(st)};
  stored_bytes_ += std::uint64_t(st.st_size);
}

bool AssetStore::contains(const std::string& hash) const {
  std::lock_guard lock(mutex_);
  adopt_locked(hash);
  return index_.count(hash) > 0;
}

std::optional<std::uint64_t> AssetStore::size_of(const std::string& hash) const {
  std::lock_guard lock(mutex_);
  adopt_locked(hash);
  const auto it = index_.find(hash);
  if (it == index_.end()) return std::nullopt;
  return it->second.size;
}

std::vector<std::string> AssetStore::missing(const std::vector<std::string>& hashes) const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> out;
  for (const std::string& h : hashes) adopt_locked(h);
  for (const std::string& h : hashes)
    if (!index_.count(h) && std::find(out.begin(), out.end(), h) == out.end()) out.push_back(h);
  return out;
}

std::uint64_t AssetStore::stored_bytes() const {
  std::lock_guard lock(mutex_);
  return stored_bytes_;
}

std::size_t AssetStore::stored_count() const {
  std::lock_guard lock(mutex_);
  return index_.size();
}

std::optional<std::pair<std::shared_ptr<std::ifstream>, std::uint64_t>> AssetStore::open(
    const std::string& hash) const {
  std::lock_guard lock(mutex_);
  adopt_locked(hash);
  const auto it = index_.find(hash);
  if (it == index_.end()) return std::nullopt;
  auto stream = std::make_shared<std::ifstream>(asset_path(hash), std::ios::binary);
  if (!*stream) return std::nullopt;
  return std::make_pair(std::move(stream), it->second.size);
}

std::unique_ptr<AssetUpload> AssetStore::begin_upload(const std::string& expected_hash) {
  return std::make_unique<AssetUpload>(expected_hash, root_ + "/tmp/" + random_name() + ".part",
                                       limits_.max_asset_bytes);
}

PutResult AssetStore::put_bytes(std::string_view bytes, std::string* hash_out) {
  const std::string hash = sha256_hex(bytes);
  if (hash_out) *hash_out = hash;
  if (const auto size = size_of(hash)) return PutResult{PutStatus::kAlreadyStored, hash, *size};
  auto upload = begin_upload(hash);
  upload->write(bytes.data(), bytes.size());
  return finish_upload(std::move(upload));
}

std::string AssetStore::stage(const std::string& hash, const std::string& name) {
  std::lock_guard lock(mutex_);  // not evicted between the check and the link
  const fs::path folder = fs::path(root_) / "tmp" / random_name();
  fs::create_directories(folder);
  const fs::path file = folder / name;
  if (::link(asset_path(hash).c_str(), file.c_str()) != 0) {
    std::error_code ec;
    fs::remove_all(folder, ec);
    throw std::runtime_error("cannot stage " + hash + ": " + std::strerror(errno));
  }
  return file.string();
}

void AssetStore::unstage(const std::string& staged_path) {
  std::error_code ec;
  fs::remove_all(fs::path(staged_path).parent_path(), ec);
}

PutResult AssetStore::finish_upload(std::unique_ptr<AssetUpload> upload) {
  PutResult out;
  out.size = upload->size_;
  if (upload->too_large_) {
    out.status = PutStatus::kTooLarge;
    return out;
  }
  out.actual_hash = upload->hash_.hex_digest();
  if (out.actual_hash != upload->expected_) {
    out.status = PutStatus::kMismatch;
    return out;
  }
  // On disk before the rename makes it visible: a crash can never leave a short file under the
  // hash of a longer one.
  if (::fsync(upload->fd_) != 0 || ::close(upload->fd_) != 0) {
    upload->fd_ = -1;
    throw std::runtime_error("cannot flush " + upload->tmp_path_ + ": " + std::strerror(errno));
  }
  upload->fd_ = -1;
  std::lock_guard lock(mutex_);
  adopt_locked(out.actual_hash);
  if (index_.count(out.actual_hash)) {
    out.status = PutStatus::kAlreadyStored;
    return out;
  }
  if (!make_room_locked(out.size)) {
    out.status = PutStatus::kNoRoom;
    return out;
  }
  const std::string final_path = asset_path(out.actual_hash);
  if (::rename(upload->tmp_path_.c_str(), final_path.c_str()) != 0)
    throw std::runtime_error("cannot rename into " + final_path + ": " + std::strerror(errno));
  upload->moved_ = true;
  fsync_dir(root_ + "/sha256");
  index_[out.actual_hash] = Entry{out.size, now_ns()};
  stored_bytes_ += out.size;
  out.status = PutStatus::kStored;
  return out;
}

bool AssetStore::make_room_locked(std::uint64_t incoming) {
  if (incoming > limits_.max_store_bytes) return false;
  if (stored_bytes_ + incoming <= limits_.max_store_bytes) return true;
  // Folders of finished jobs pin their files; let them go first.
  sweep_locked();
  std::vector<std::pair<std::int64_t, std::string>> by_age;
  for (const auto& [hash, e] : index_) by_age.emplace_back(e.last_used_ns, hash);
  std::sort(by_age.begin(), by_age.end());
  // Chosen first, removed only if they make enough room: a refused upload evicts nothing.
  std::vector<std::string> victims;
  std::uint64_t freed = 0;
  for (const auto& [age, hash] : by_age) {
    if (stored_bytes_ - freed + incoming <= limits_.max_store_bytes) break;
    struct stat st {};
    if (::stat(asset_path(hash).c_str(), &st) == 0 && st.st_nlink > 1) continue;  // in a job's folder
    victims.push_back(hash);
    freed += index_[hash].size;
  }
  if (stored_bytes_ - freed + incoming > limits_.max_store_bytes) return false;
  for (const std::string& hash : victims) {
    if (::unlink(asset_path(hash).c_str()) != 0 && errno != ENOENT) continue;
    stored_bytes_ -= index_[hash].size;
    index_.erase(hash);
  }
  return stored_bytes_ + incoming <= limits_.max_store_bytes;
}

JobLinkResult AssetStore::link_job_folder(const std::string& job_id,
                                          const std::vector<api::ManifestEntry>& manifest) {
  JobLinkResult out;
  std::lock_guard lock(mutex_);
  for (const api::ManifestEntry& m : manifest) {
    adopt_locked(m.hash);
    const auto it = index_.find(m.hash);
    if (it == index_.end()) out.missing.push_back(m.name);
    else out.total_bytes += it->second.size;
  }
  if (!out.ok()) return out;
  const fs::path folder = job_folder(job_id);
  fs::remove_all(folder);
  fs::create_directories(folder);
  pending_jobs_.insert(job_id);
  std::set<std::string> dirs = {folder.string()};
  const std::int64_t now = now_ns();
  try {
    for (const api::ManifestEntry& m : manifest) {
      // Names were checked (api::manifest_name_problem): relative, no "." or "..", so the link
      // lands inside the folder.
      const fs::path target = folder / m.name;
      fs::create_directories(target.parent_path());
      for (fs::path p = target.parent_path(); p != folder && p.has_relative_path();
           p = p.parent_path())
        dirs.insert(p.string());
      const std::string source = asset_path(m.hash);
      if (::link(source.c_str(), target.c_str()) != 0)
        throw std::runtime_error("cannot link " + target.string() + ": " + std::strerror(errno));
      // The last use decides the order of eviction.
      const struct timespec times[2] = {{0, UTIME_OMIT}, {now / 1'000'000'000, now % 1'000'000'000}};
      ::utimensat(AT_FDCWD, source.c_str(), times, 0);
      index_[m.hash].last_used_ns = now;
    }
    for (const std::string& d : dirs) fsync_dir(d);
    fsync_dir(root_ + "/jobs");
  } catch (...) {
    pending_jobs_.erase(job_id);
    std::error_code ec;
    fs::remove_all(folder, ec);
    throw;
  }
  return out;
}

void AssetStore::commit_job_folder(const std::string& job_id) {
  std::lock_guard lock(mutex_);
  pending_jobs_.erase(job_id);
}

void AssetStore::remove_job_folder(const std::string& job_id) {
  std::lock_guard lock(mutex_);
  pending_jobs_.erase(job_id);
  std::error_code ec;
  fs::remove_all(job_folder(job_id), ec);
}

void AssetStore::sweep_job_folders() {
  std::lock_guard lock(mutex_);
  sweep_locked();
}

void AssetStore::sweep_locked() {
  if (!is_live_) return;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root_ + "/jobs", ec)) {
    const std::string id = e.path().filename().string();
    if (pending_jobs_.count(id) || is_live_(id)) continue;
    std::error_code rm;
    fs::remove_all(e.path(), rm);
  }
}

}  // namespace penumbra::server
