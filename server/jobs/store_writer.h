#pragma once
// The one thread that writes to the JobStore. Changes are queued in the order the job table
// makes them (a push under a short mutex) and applied in that order, as many as have queued
// up in one apply() call, so one commit (one fsync) serves a burst of changes. Whoever must
// not answer before a change is on disk (a 202, a DELETE) waits for its ticket; a status poll
// never waits for anything here.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/storage/job_store.h"

namespace penumbra::server {

class StoreWriter {
 public:
  using Ticket = uint64_t;  // 1, 2, 3 ... in the order of enqueue

  explicit StoreWriter(JobStore& store);
  ~StoreWriter();  // writes what is queued, then stops
  StoreWriter(const StoreWriter&) = delete;
  StoreWriter& operator=(const StoreWriter&) = delete;

  Ticket enqueue(JobChange change);
  // Blocks until the change (and every one before it) has been applied. Throws StoreError
  // when the commit that held it failed (the failure is also logged with the changes it lost).
  void wait_durable(Ticket ticket);
  // Blocks until everything queued so far has been applied or has failed.
  void flush();

 private:
  struct Failure {
    Ticket first = 0, last = 0;
    std::string message;
  };
  void run();
  void record_failure(const std::vector<JobChange>& batch, Ticket first, const std::string& what);

  JobStore& store_;
  std::mutex mutex_;
  std::condition_variable work_cv_;  // something queued, or stopping
  std::condition_variable done_cv_;  // applied_ moved
  std::vector<JobChange> pending_;
  Ticket last_enqueued_ = 0;
  Ticket applied_ = 0;            // every ticket <= applied_ has been committed or has failed
  std::deque<Failure> failures_;  // the most recent ones; older waiters are long gone
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace penumbra::server
