#include "server/jobs/job_table.h"

#include <algorithm>

namespace penumbra::server {

std::vector<std::string> JobTable::restore(std::vector<JobRecord> records) {
  std::sort(records.begin(), records.end(),
            [](const JobRecord& a, const JobRecord& b) { return a.seq < b.seq; });
  std::vector<std::string> queued;
  std::lock_guard lock(mutex_);
  for (JobRecord& r : records) {
    if (r.state == JobState::kRunning) {
      // attempts keeps the interrupted start: a job that keeps killing the server fails.
      r.state = JobState::kQueued;
      r.started_at = 0;
      journal_.enqueue(UpdateJob{r});
    }
    if (r.state == JobState::kQueued) queued.push_back(r.id);
    by_seq_[r.seq] = r.id;
    if (!r.idempotency_key.empty()) by_key_[r.idempotency_key] = r.id;
    const std::string id = r.id;  // r is moved from below
    jobs_[id] = JobEntry{std::move(r), nullptr};
  }
  return queued;
}

void JobTable::add(JobRecord record) {
  {
    std::lock_guard lock(mutex_);
    by_seq_[record.seq] = record.id;
    if (!record.idempotency_key.empty()) by_key_[record.idempotency_key] = record.id;
    const std::string id = record.id;
    const JobEntry& e = jobs_[id] = JobEntry{std::move(record), nullptr};
    if (observer_) observer_(e);
  }
  changed_.notify_all();
}

std::optional<JobEntry> JobTable::find(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  return it->second;
}

std::optional<JobRecord> JobTable::find_by_key(const std::string& key) const {
  std::lock_guard lock(mutex_);
  const auto k = by_key_.find(key);
  if (k == by_key_.end()) return std::nullopt;
  return jobs_.at(k->second).record;
}

std::vector<JobEntry> JobTable::list(std::optional<JobState> state, int64_t before_seq,
                                     int limit) const {
  std::vector<JobEntry> out;
  std::lock_guard lock(mutex_);
  auto it = before_seq > 0 ? by_seq_.lower_bound(before_seq) : by_seq_.end();
  while (it != by_seq_.begin() && int(out.size()) < limit) {
    --it;
    const JobEntry& e = jobs_.at(it->second);
    if (state ? e.record.state == *state : e.record.state != JobState::kDeleted) out.push_back(e);
  }
  return out;
}

std::map<JobState, int64_t> JobTable::count_by_state() const {
  std::map<JobState, int64_t> out;
  std::lock_guard lock(mutex_);
  for (const auto& [id, e] : jobs_) ++out[e.record.state];
  return out;
}

std::vector<std::shared_ptr<JobRuntime>> JobTable::runtimes() const {
  std::vector<std::shared_ptr<JobRuntime>> out;
  std::lock_guard lock(mutex_);
  for (const auto& [id, e] : jobs_)
    if (e.runtime) out.push_back(e.runtime);
  return out;
}

std::optional<StoreWriter::Ticket> JobTable::modify(const std::string& id,
                                                    const std::function<bool(JobEntry&)>& change) {
  std::optional<StoreWriter::Ticket> ticket;
  {
    std::lock_guard lock(mutex_);
    const auto it = jobs_.find(id);
    if (it == jobs_.end()) return std::nullopt;
    JobEntry& e = it->second;
    const std::string key_before = e.record.idempotency_key;
    if (!change(e)) return std::nullopt;
    if (e.record.idempotency_key != key_before) {
      by_key_.erase(key_before);
      if (!e.record.idempotency_key.empty()) by_key_[e.record.idempotency_key] = id;
    }
    ticket = journal_.enqueue(UpdateJob{e.record});
    if (observer_) observer_(e);
  }
  changed_.notify_all();
  return ticket;
}

std::vector<std::string> JobTable::take_expired(double finished_before) {
  std::vector<std::string> ids;
  {
    std::lock_guard lock(mutex_);
    for (auto it = jobs_.begin(); it != jobs_.end();) {
      const JobRecord& r = it->second.record;
      if ((is_finished(r.state) || r.state == JobState::kDeleted) &&
          r.finished_at < finished_before) {
        ids.push_back(r.id);
        by_seq_.erase(r.seq);
        if (!r.idempotency_key.empty()) by_key_.erase(r.idempotency_key);
        journal_.enqueue(EraseJob{r.id});
        it = jobs_.erase(it);
      } else {
        ++it;
      }
    }
  }
  if (!ids.empty()) changed_.notify_all();
  return ids;
}

std::optional<JobRecord> JobTable::wait(const std::string& id,
                                        std::chrono::steady_clock::time_point deadline,
                                        const std::function<bool(const JobRecord&)>& done,
                                        const std::function<bool()>& give_up) const {
  std::unique_lock lock(mutex_);
  for (;;) {
    const auto it = jobs_.find(id);
    if (it == jobs_.end()) return std::nullopt;
    if (done(it->second.record) || give_up() || std::chrono::steady_clock::now() >= deadline)
      return it->second.record;
    // The timeout bounds a wake-up missed by give_up(), which is not set under this lock.
    changed_.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() +
                                                     std::chrono::milliseconds(500)));
  }
}

void JobTable::wake_all() {
  { std::lock_guard lock(mutex_); }  // a waiter between its check and its wait sees the wake-up
  changed_.notify_all();
}

}  // namespace penumbra::server
