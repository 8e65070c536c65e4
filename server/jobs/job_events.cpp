#include "server/jobs/job_events.h"

#include <algorithm>

namespace penumbra::server {

JobEvents::JobEvents() {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  // 1024 x ms stays below 2^53 until the year 2245: ids survive a JavaScript Number.
  next_id_ = uint64_t(std::max<int64_t>(ms, 1)) * 1024;
}

uint64_t JobEvents::append(JobEvent event) {
  event.id = next_id_++;
  History& h = jobs_[event.record.id];
  if (!event.progress_only) {
    // A state change supersedes the progress sample before it.
    if (!h.events.empty() && h.events.back().progress_only) h.events.pop_back();
  } else if (!h.events.empty() && h.events.back().progress_only) {
    h.events.pop_back();  // only the latest progress is kept
  }
  if (is_finished(event.record.state)) {
    // A finished job keeps its state changes only.
    h.events.erase(std::remove_if(h.events.begin(), h.events.end(),
                                  [](const JobEvent& e) { return e.progress_only; }),
                   h.events.end());
  }
  h.events.push_back(std::move(event));
  while (h.events.size() > kMaxEventsPerJob) h.events.pop_front();
  h.last_event_at = std::chrono::steady_clock::now();
  changed_.notify_all();
  return h.events.back().id;
}

uint64_t JobEvents::record_change(const JobRecord& record,
                                  std::optional<std::size_t> queue_position) {
  std::lock_guard lock(mutex_);
  if (record.state == JobState::kDeleted) {
    jobs_.erase(record.id);
    changed_.notify_all();
    return 0;
  }
  JobEvent e;
  e.record = record;
  e.queue_position = queue_position;
  return append(std::move(e));
}

void JobEvents::sample_progress(const JobRecord& record, const RenderProgress& progress) {
  std::lock_guard lock(mutex_);
  const auto it = jobs_.find(record.id);
  if (it != jobs_.end() && !it->second.events.empty()) {
    const History& h = it->second;
    if (std::chrono::steady_clock::now() - h.last_event_at < kProgressInterval) return;
    const JobEvent& last = h.events.back();
    if (last.record.state != JobState::kRunning) {
      if (last.record.state != record.state) return;  // the table's change is on its way
    }
    if (last.progress && last.progress->samples_done == progress.samples_done &&
        last.progress->passes_done == progress.passes_done)
      return;  // nothing moved
  }
  JobEvent e;
  e.record = record;
  e.progress = progress;
  e.progress_only = true;
  append(std::move(e));
}

std::vector<JobEvent> JobEvents::after(const std::string& job, uint64_t after) const {
  std::lock_guard lock(mutex_);
  std::vector<JobEvent> out;
  const auto it = jobs_.find(job);
  if (it == jobs_.end()) return out;
  for (const JobEvent& e : it->second.events)
    if (e.id > after) out.push_back(e);
  return out;
}

uint64_t JobEvents::latest_id(const JobRecord& record, std::optional<std::size_t> queue_position) {
  std::lock_guard lock(mutex_);
  const auto it = jobs_.find(record.id);
  if (it != jobs_.end() && !it->second.events.empty()) return it->second.events.back().id;
  JobEvent e;
  e.record = record;
  e.queue_position = queue_position;
  return append(std::move(e));
}

void JobEvents::wait(const std::string& job, uint64_t after,
                     std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock lock(mutex_);
  const uint64_t generation = wake_generation_;
  changed_.wait_until(lock, deadline, [&] {
    if (wake_generation_ != generation) return true;
    const auto it = jobs_.find(job);
    if (it == jobs_.end()) return true;  // forgotten: the stream ends
    return !it->second.events.empty() && it->second.events.back().id > after;
  });
}

void JobEvents::forget(const std::string& job) {
  std::lock_guard lock(mutex_);
  jobs_.erase(job);
  changed_.notify_all();
}

void JobEvents::wake_all() {
  std::lock_guard lock(mutex_);
  ++wake_generation_;
  changed_.notify_all();
}

bool JobEvents::try_open_stream(int max_streams) {
  std::lock_guard lock(mutex_);
  if (open_streams_ >= max_streams) return false;
  ++open_streams_;
  return true;
}

void JobEvents::close_stream() {
  std::lock_guard lock(mutex_);
  --open_streams_;
}

int JobEvents::open_streams() const {
  std::lock_guard lock(mutex_);
  return open_streams_;
}

}  // namespace penumbra::server
