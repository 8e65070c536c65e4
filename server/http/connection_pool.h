#pragma once
// The task queue cpp-httplib hands each accepted connection to. The library serves a connection on
// one thread from accept to close, so a fixed pool of N threads is taken down by N slow clients
// (issue 15). This pool grows on demand up to max_threads, and threads idle for idle_exit go away
// again; a blocked connection thread costs its touched stack pages (tens of KB), not CPU. Beyond
// max_threads a connection is run on the accepting thread in "shed" mode: GuardedServer answers
// 503 at once without reading (is_shedding()).
#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>

namespace penumbra::server {

class ConnectionPool : public httplib::TaskQueue {
 public:
  ConnectionPool(std::size_t max_threads, std::chrono::seconds idle_exit);
  ~ConnectionPool() override;
  void enqueue(std::function<void()> fn) override;
  void shutdown() override;

  // True on the thread that runs a connection the pool had no room for.
  static bool is_shedding();
  std::size_t threads() const;

 private:
  void work();
  const std::size_t max_threads_;
  const std::chrono::seconds idle_exit_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable all_exited_;
  std::deque<std::function<void()>> jobs_;
  std::size_t threads_ = 0;
  std::size_t idle_ = 0;
  bool shutdown_ = false;
};

}  // namespace penumbra::server
