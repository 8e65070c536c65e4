#include "server/jobs/job_queue.h"

#include <algorithm>

namespace penumbra::server {

JobQueue::PushResult JobQueue::push(const std::string& id, bool force) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return PushResult::kClosed;
    if (!force && ids_.size() >= capacity_) return PushResult::kFull;
    ids_.push_back(id);
  }
  cv_.notify_one();
  return PushResult::kPushed;
}

std::optional<std::string> JobQueue::pop() {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return closed_ || !ids_.empty(); });
  if (closed_) return std::nullopt;
  std::string id = std::move(ids_.front());
  ids_.pop_front();
  return id;
}

bool JobQueue::remove(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = std::find(ids_.begin(), ids_.end(), id);
  if (it == ids_.end()) return false;
  ids_.erase(it);
  return true;
}

std::optional<std::size_t> JobQueue::position(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = std::find(ids_.begin(), ids_.end(), id);
  if (it == ids_.end()) return std::nullopt;
  return std::size_t(it - ids_.begin());
}

std::size_t JobQueue::size() const {
  std::lock_guard lock(mutex_);
  return ids_.size();
}

bool JobQueue::full() const {
  std::lock_guard lock(mutex_);
  return ids_.size() >= capacity_;
}

void JobQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

}  // namespace penumbra::server
