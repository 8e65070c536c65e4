#pragma once
// The queued job ids in run order, with a capacity: higher priority first, submission order
// (seq) within a priority (render-farm convention: Flamenco, OpenCue and Deadline all run the
// highest priority first and first-come-first-served among equals). Thread-safe; workers block
// in pop().
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>

namespace penumbra::server {

class JobQueue {
 public:
  explicit JobQueue(std::size_t capacity) : capacity_(capacity) {}

  enum class PushResult { kPushed, kFull, kClosed };
  // `force` ignores the capacity: jobs recovered at startup were already accepted.
  PushResult push(const std::string& id, int priority, int64_t seq, bool force = false);
  // Blocks until a job is queued (returns the first in run order) or the queue is closed
  // (returns nullopt).
  std::optional<std::string> pop();
  // Removes a queued job (cancel); false if it is not queued (already popped, or unknown).
  bool remove(const std::string& id);
  // 0 = next to run; nullopt = not queued.
  std::optional<std::size_t> position(const std::string& id) const;
  std::size_t size() const;
  std::size_t capacity() const { return capacity_; }
  bool full() const;
  // pop() returns nullopt from now on; queued ids stay (they are durable in the store).
  void close();

 private:
  struct Entry {
    int priority;
    int64_t seq;
    std::string id;
  };
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Entry> entries_;  // in run order
  bool closed_ = false;
};

}  // namespace penumbra::server
