#include "server/http/connection_pool.h"

#include <thread>

namespace penumbra::server {
namespace {
thread_local bool t_shedding = false;
}

ConnectionPool::ConnectionPool(std::size_t max_threads, std::chrono::seconds idle_exit)
    : max_threads_(std::max<std::size_t>(1, max_threads)), idle_exit_(idle_exit) {}

ConnectionPool::~ConnectionPool() { shutdown(); }

bool ConnectionPool::is_shedding() { return t_shedding; }

std::size_t ConnectionPool::threads() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return threads_;
}

void ConnectionPool::enqueue(std::function<void()> fn) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (shutdown_) return;
  const auto now = std::chrono::steady_clock::now();
  if (jobs_.size() < threads_ - busy_) {  // a free thread takes it
    jobs_.push_back({std::move(fn), now});
    wake_.notify_one();
    return;
  }
  if (threads_ < max_threads_) {
    jobs_.push_back({std::move(fn), now});
    ++threads_;
    // Detached: an idle thread leaves on its own; shutdown() waits for the count to reach 0.
    std::thread([this] { work(); }).detach();
    return;
  }
  if (jobs_.size() < max_threads_) {  // the next thread to finish takes it (see the header)
    jobs_.push_back({std::move(fn), now});
    return;
  }
  lock.unlock();
  t_shedding = true;
  fn();
  t_shedding = false;
}

void ConnectionPool::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (jobs_.empty()) {
      const bool woke =
          wake_.wait_for(lock, idle_exit_, [this] { return !jobs_.empty() || shutdown_; });
      if (!woke || (jobs_.empty() && shutdown_)) break;
    }
    if (jobs_.empty()) continue;
    Pending job = std::move(jobs_.front());
    jobs_.pop_front();
    ++busy_;
    lock.unlock();
    const bool late = std::chrono::steady_clock::now() - job.queued > kShedAfter;
    t_shedding = late;
    job.fn();
    t_shedding = false;
    lock.lock();
    --busy_;
  }
  --threads_;
  all_exited_.notify_all();
}

void ConnectionPool::shutdown() {
  std::unique_lock<std::mutex> lock(mutex_);
  shutdown_ = true;
  wake_.notify_all();
  all_exited_.wait(lock, [this] { return threads_ == 0; });
}

}  // namespace penumbra::server
