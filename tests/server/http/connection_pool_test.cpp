// The connection pool sheds (503) only when every thread is running a connection: a thread that
// has just finished one counts as free, so back-to-back connections at the cap are served.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "server/http/connection_pool.h"

namespace penumbra::test {
namespace {

TEST(ConnectionPool, BackToBackConnectionsAtTheCapAreNotShed) {
  server::ConnectionPool pool(2, std::chrono::seconds(10));
  // One connection stays open throughout: one of the two threads is busy.
  std::mutex m;
  std::condition_variable cv;
  bool release = false;
  pool.enqueue([&] {
    std::unique_lock<std::mutex> lock(m);
    cv.wait(lock, [&] { return release; });
  });
  // Then connections one after another, each arriving the moment the previous one finished:
  // the second thread is then between connections, not in its wait yet.
  std::atomic<int> shed{0}, done{0};
  constexpr int kConnections = 20000;
  for (int i = 0; i < kConnections; ++i) {
    const int before = done.load();
    pool.enqueue([&] {
      if (server::ConnectionPool::is_shedding()) ++shed;
      ++done;
    });
    while (done.load() == before) std::this_thread::yield();
  }
  {
    std::lock_guard<std::mutex> lock(m);
    release = true;
  }
  cv.notify_all();
  EXPECT_EQ(shed.load(), 0) << "of " << kConnections;
  EXPECT_LE(pool.threads(), 2u);
}

// Every thread busy: a new connection waits in a queue as long as the pool has threads; with
// the queue full it is answered at once (shed), and one that waited past kShedAfter is shed too.
TEST(ConnectionPool, ShedsWhenEveryThreadIsBusyAndTheQueueIsFull) {
  server::ConnectionPool pool(1, std::chrono::seconds(10));
  std::mutex m;
  std::condition_variable cv;
  bool release = false, started = false;
  pool.enqueue([&] {
    std::unique_lock<std::mutex> lock(m);
    started = true;
    cv.notify_all();
    cv.wait(lock, [&] { return release; });
  });
  {
    std::unique_lock<std::mutex> lock(m);
    cv.wait(lock, [&] { return started; });
  }
  std::atomic<int> queued_ran{0};
  std::atomic<bool> queued_was_shed{false};
  pool.enqueue([&] {  // queued: the one slot of a one-thread pool
    queued_was_shed = server::ConnectionPool::is_shedding();
    ++queued_ran;
  });
  bool was_shed = false;
  pool.enqueue([&] { was_shed = server::ConnectionPool::is_shedding(); });
  EXPECT_TRUE(was_shed);  // queue full: run at once on this thread, in shed mode
  EXPECT_EQ(queued_ran.load(), 0);
  std::this_thread::sleep_for(server::ConnectionPool::kShedAfter + std::chrono::milliseconds(100));
  {
    std::lock_guard<std::mutex> lock(m);
    release = true;
  }
  cv.notify_all();
  while (queued_ran.load() == 0) std::this_thread::yield();
  EXPECT_TRUE(queued_was_shed.load()) << "it waited longer than kShedAfter";
}

}  // namespace
}  // namespace penumbra::test
