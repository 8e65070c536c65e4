#pragma once
// The authoritative state of every job, in memory, under one short mutex. Every change is made
// here and, under the same lock, queued for the store (StoreWriter), so the store sees changes
// in exactly the order the table made them while nobody holding this lock ever waits for a
// disk. Status polls and listings read only this table.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "server/jobs/job_runtime.h"
#include "server/jobs/store_writer.h"
#include "server/storage/job_record.h"

namespace penumbra::server {

struct JobEntry {
  JobRecord record;
  std::shared_ptr<JobRuntime> runtime;  // while running
};

class JobTable {
 public:
  explicit JobTable(StoreWriter& journal) : journal_(journal) {}

  // At startup, before other threads use the table: the stored records. Jobs stored as running
  // were interrupted (crash, kill -9) and go back to the queue. Returns the queued ids in
  // submission order.
  std::vector<std::string> restore(std::vector<JobRecord> records);
  // A new job, already durable in the store.
  void add(JobRecord record);

  std::optional<JobEntry> find(const std::string& id) const;
  // The job holding this idempotency key, if any.
  std::optional<JobRecord> find_by_key(const std::string& key) const;
  // Newest first; jobs with seq < before_seq (0 = from the newest); tombstones never.
  std::vector<JobEntry> list(std::optional<JobState> state, int64_t before_seq, int limit) const;
  std::map<JobState, int64_t> count_by_state() const;
  std::vector<std::shared_ptr<JobRuntime>> runtimes() const;

  // Calls change(entry) under the lock. When it returns true, the record it left is queued for
  // the store and waiters are woken; the ticket is returned. nullopt: no such job, or no change.
  std::optional<StoreWriter::Ticket> modify(const std::string& id,
                                            const std::function<bool(JobEntry&)>& change);
  // Finished jobs and tombstones finished before the time: removed (and erased from the store).
  std::vector<std::string> take_expired(double finished_before);

  // Blocks until done(record) holds, the job is gone, give_up() is true or the deadline passes;
  // returns the record as it was then (nullopt when gone). Woken by every change and wake_all().
  std::optional<JobRecord> wait(const std::string& id,
                                std::chrono::steady_clock::time_point deadline,
                                const std::function<bool(const JobRecord&)>& done,
                                const std::function<bool()>& give_up) const;
  void wake_all();
  // Called under the lock after every add() and every change modify() makes, with the entry as
  // it now is (the job events and the webhook sender listen here). Set before other threads use
  // the table; it must take no lock but its own leaf ones and never call back into the table.
  void set_observer(std::function<void(const JobEntry&)> observer) {
    observer_ = std::move(observer);
  }

 private:
  std::function<void(const JobEntry&)> observer_;
  StoreWriter& journal_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::unordered_map<std::string, JobEntry> jobs_;
  std::map<int64_t, std::string> by_seq_;
  std::unordered_map<std::string, std::string> by_key_;  // idempotency key -> id
};

}  // namespace penumbra::server
