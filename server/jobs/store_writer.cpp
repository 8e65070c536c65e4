#include "server/jobs/store_writer.h"

#include <cstdio>

namespace penumbra::server {
namespace {

// Failures kept for wait_durable(); a waiter asks within milliseconds of its enqueue.
constexpr std::size_t kFailuresKept = 64;
// Ids named in one log line about a failed commit.
constexpr std::size_t kChangesLogged = 8;

}  // namespace

StoreWriter::StoreWriter(JobStore& store) : store_(store), thread_([this] { run(); }) {}

StoreWriter::~StoreWriter() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  work_cv_.notify_all();
  thread_.join();
}

StoreWriter::Ticket StoreWriter::enqueue(JobChange change) {
  Ticket ticket;
  {
    std::lock_guard lock(mutex_);
    pending_.push_back(std::move(change));
    ticket = ++last_enqueued_;
  }
  work_cv_.notify_one();
  return ticket;
}

void StoreWriter::wait_durable(Ticket ticket) {
  std::unique_lock lock(mutex_);
  done_cv_.wait(lock, [&] { return applied_ >= ticket; });
  for (const Failure& f : failures_)
    if (ticket >= f.first && ticket <= f.last) throw StoreError(f.message);
}

void StoreWriter::flush() {
  std::unique_lock lock(mutex_);
  const Ticket target = last_enqueued_;
  done_cv_.wait(lock, [&] { return applied_ >= target; });
}

void StoreWriter::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    work_cv_.wait(lock, [&] { return stopping_ || !pending_.empty(); });
    if (pending_.empty()) return;  // stopping, and everything is written
    std::vector<JobChange> batch;
    batch.swap(pending_);
    const Ticket first = applied_ + 1;
    const Ticket last = last_enqueued_;
    lock.unlock();
    std::string error;
    try {
      store_.apply(batch);
    } catch (const std::exception& e) {
      error = e.what();
    } catch (...) {
      error = "unknown exception";
    }
    if (!error.empty()) record_failure(batch, first, error);
    lock.lock();
    if (!error.empty()) {
      failures_.push_back({first, last, error});
      if (failures_.size() > kFailuresKept) failures_.pop_front();
    }
    applied_ = last;
    done_cv_.notify_all();
  }
}

void StoreWriter::record_failure(const std::vector<JobChange>& batch, Ticket first,
                                 const std::string& what) {
  // The memory state keeps these changes, the disk does not: a restart would show the jobs as
  // they were before. Said loudly, with the jobs concerned, since no client request fails for
  // most of them.
  std::string changes;
  for (std::size_t i = 0; i < batch.size() && i < kChangesLogged; ++i)
    changes += (i ? ", " : "") + describe(batch[i]);
  if (batch.size() > kChangesLogged) changes += ", ...";
  std::fprintf(stderr,
               "penumbra serve: store: commit of %zu change(s) [%s] (tickets %llu..) failed: %s\n",
               batch.size(), changes.c_str(), static_cast<unsigned long long>(first), what.c_str());
}

}  // namespace penumbra::server
