#include "server/storage/file_result_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "server/storage/result_files.h"

namespace penumbra::server {
namespace fs = std::filesystem;

namespace {
void fsync_dir(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}
}  // namespace

FileResultStore::FileResultStore(const std::string& data_dir, bool shared)
    : dir_((fs::path(data_dir) / "results").string()) {
  fs::create_directories(dir_);
  if (shared) return;
  const auto remove_temporaries = [](const fs::path& dir) {
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().filename().string().find(".tmp") != std::string::npos)
        fs::remove(entry.path());
  };
  remove_temporaries(dir_);
  for (const auto& entry : fs::directory_iterator(dir_))
    if (entry.is_directory()) remove_temporaries(entry.path());  // an animation's frames
}

std::string FileResultStore::path(const std::string& id, const std::string& format) const {
  // An animation's frame keys ("frames/17.png") live in one folder per job, DIR/<id>.frames/, so
  // a job of 1000 frames is removed as one folder and the results folder stays short.
  if (format.rfind(kFramesKeyPrefix, 0) == 0)
    return (fs::path(frames_dir(id)) / format.substr(std::string(kFramesKeyPrefix).size())).string();
  return (fs::path(dir_) / (id + "." + format)).string();
}

std::string FileResultStore::frames_dir(const std::string& id) const {
  return (fs::path(dir_) / (id + ".frames")).string();
}

std::optional<StoredResult> FileResultStore::open(const std::string& id,
                                                  const std::string& format) const {
  const std::string file = path(id, format);
  auto stream = std::make_shared<std::ifstream>(file, std::ios::binary);
  if (!*stream) return std::nullopt;
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) return std::nullopt;
  return StoredResult{std::move(stream), size};
}

void FileResultStore::write(const std::string& id, const std::string& format,
                            const std::vector<uint8_t>& bytes) {
  const std::string final_path = path(id, format);
  const std::string tmp = final_path + ".tmp";
  const std::string parent = fs::path(final_path).parent_path().string();
  if (parent != dir_ && !fs::is_directory(parent)) {
    // The job's frames folder, made durable with its first frame: its entry in dir_ is fsync'd.
    fs::create_directories(parent);
    fsync_dir(dir_);
  }
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + tmp + ": " + std::strerror(errno));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string err = std::strerror(errno);
      ::close(fd);
      ::unlink(tmp.c_str());
      throw std::runtime_error("cannot write " + tmp + ": " + err);
    }
    done += std::size_t(n);
  }
  // The data must be on disk before the rename makes it visible, or a crash could leave a
  // complete-looking but empty file.
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(tmp.c_str());
    throw std::runtime_error("cannot flush " + tmp);
  }
  if (::rename(tmp.c_str(), final_path.c_str()) != 0) {
    ::unlink(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + ": " + std::strerror(errno));
  }
  fsync_dir(parent);
}

void FileResultStore::remove(const std::string& id) {
  std::error_code ec;
  for (const std::string& key : all_result_keys()) fs::remove(path(id, key), ec);
  fs::remove_all(frames_dir(id), ec);
}

}  // namespace penumbra::server
