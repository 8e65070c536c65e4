#pragma once
// Where finished images are kept, by job id and format ("png", "exr"). One implementation
// today (files beside the database, file_result_store.h); an object store would be another.
#include <cstdint>
#include <istream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace penumbra::server {

struct StoredResult {
  std::shared_ptr<std::istream> stream;  // stays readable if the result is removed meanwhile
  std::uint64_t size = 0;
};

class ResultStore {
 public:
  virtual ~ResultStore() = default;
  // Whole or not at all, and durable when it returns: a reader, or a restart after kill -9,
  // sees the complete image or none. Throws std::runtime_error.
  virtual void write(const std::string& id, const std::string& format,
                     const std::vector<uint8_t>& bytes) = 0;
  // nullopt when there is no such result.
  virtual std::optional<StoredResult> open(const std::string& id,
                                           const std::string& format) const = 0;
  // Every format of the job; a missing result is fine.
  virtual void remove(const std::string& id) = 0;
};

}  // namespace penumbra::server
