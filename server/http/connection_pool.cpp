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
  if (jobs_.size() < idle_) {
    jobs_.push_back(std::move(fn));
    wake_.notify_one();
    return;
  }
  if (threads_ < max_threads_) {
    jobs_.push_back(std::move(fn));
    ++threads_;
    // Detached: an idle thread leaves on its own; shutdown() waits for the count to reach 0.
    std::thread([this] { work(); }).detach();
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
      ++idle_;
      const bool woke =
          wake_.wait_for(lock, idle_exit_, [this] { return !jobs_.empty() || shutdown_; });
      --idle_;
      if (!woke || (jobs_.empty() && shutdown_)) break;
    }
    if (jobs_.empty()) continue;
    auto fn = std::move(jobs_.front());
    jobs_.pop_front();
    lock.unlock();
    fn();
    lock.lock();
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
