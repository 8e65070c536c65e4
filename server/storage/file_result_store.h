#pragma once
// Result images as files: DIR/results/<id>.png and .exr (an animation's frames in
// DIR/results/<id>.frames/<frame>.png ...), each written to a temporary file,
// flushed to disk and renamed, so a reader (or a restart after kill -9) sees a whole file or none.
#include <string>

#include "server/storage/result_store.h"

namespace penumbra::server {

class FileResultStore final : public ResultStore {
 public:
  // Creates DIR/results and removes stale temp files, unless `shared` (a farm's volume: the
  // temp files may be another node's writes under way; each attempt's names are its own).
  explicit FileResultStore(const std::string& data_dir, bool shared = false);
  void write(const std::string& id, const std::string& format,
             const std::vector<uint8_t>& bytes) override;
  std::optional<StoredResult> open(const std::string& id, const std::string& format) const override;
  void remove(const std::string& id) override;
  std::string path(const std::string& id, const std::string& format) const;
  // DIR/results/<id>.frames: an animation's frames (keys "frames/<frame>.<key>", result_files.h).
  std::string frames_dir(const std::string& id) const;

 private:
  std::string dir_;
};

}  // namespace penumbra::server
