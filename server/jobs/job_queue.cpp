#include "server/jobs/job_queue.h"

#include <algorithm>

namespace penumbra::server {

JobQueue::PushResult JobQueue::push(const std::string& id, int priority, int64_t seq, bool force) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return PushResult::kClosed;
    if (!force && entries_.size() >= capacity_) return PushResult::kFull;
    // After every entry that runs before it: higher priority, or equal priority and older.
    const auto at = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) {
      return e.priority < priority || (e.priority == priority && e.seq > seq);
    });
    entries_.insert(at, Entry{priority, seq, id});
  }
  cv_.notify_one();
  return PushResult::kPushed;
}

std::optional<std::string> JobQueue::pop() {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return closed_ || !entries_.empty(); });
  if (closed_) return std::nullopt;
  std::string id = std::move(entries_.front().id);
  entries_.pop_front();
  return id;
}

bool JobQueue::remove(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it =
      std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.id == id; });
  if (it == entries_.end()) return false;
  entries_.erase(it);
  return true;
}

std::optional<std::size_t> JobQueue::position(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it =
      std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.id == id; });
  if (it == entries_.end()) return std::nullopt;
  return std::size_t(it - entries_.begin());
}

std::size_t JobQueue::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

bool JobQueue::full() const {
  std::lock_guard lock(mutex_);
  return entries_.size() >= capacity_;
}

void JobQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

}  // namespace penumbra::server
