#pragma once
// The FIFO of queued job ids with a capacity. Thread-safe; workers block in pop().
#include <chrono>
#include <condition_variable>
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
  PushResult push(const std::string& id, bool force = false);
  // Blocks until a job is queued (returns it) or the queue is closed (returns nullopt).
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
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::string> ids_;
  bool closed_ = false;
};

}  // namespace penumbra::server
