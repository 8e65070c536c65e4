#pragma once
// The task queue cpp-httplib hands each accepted connection to. The library serves a connection on
// one thread from accept to close, so a fixed pool of N threads is taken down by N slow clients
// (issue 15). This pool grows on demand up to max_threads, and threads idle for idle_exit go away
// again; a blocked connection thread costs its touched stack pages (tens of KB), not CPU. Beyond
// max_threads a connection waits in a short queue (at most max_threads entries) for the next
// thread to finish; one that waited longer than kShedAfter, or that finds the queue full, is run
// in "shed" mode: GuardedServer answers 503 at once without reading (is_shedding()). The queue
// matters at the cap: a keep-alive client sees its response before the server thread has left
// the connection, and reconnects within microseconds; shedding it then would answer 503 with
// fewer than max_threads clients connected.
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

  // How long a connection may wait for a thread before it is answered 503.
  static constexpr std::chrono::milliseconds kShedAfter{500};

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
  struct Pending {
    std::function<void()> fn;
    std::chrono::steady_clock::time_point queued;
  };
  std::deque<Pending> jobs_;
  std::size_t threads_ = 0;
  std::size_t busy_ = 0;  // threads running a connection; the others are free
  bool shutdown_ = false;
};

}  // namespace penumbra::server
