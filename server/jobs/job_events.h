#pragma once
// The change history GET /v1/jobs/{id}/events streams (Server-Sent Events): per job, the
// snapshots taken at each state change and, while it renders, at most one progress snapshot
// every kProgressInterval, each with an event id.
//
// Event ids are one counter for the whole server, started at 1024 x the Unix time in
// milliseconds, so they increase across events, jobs and restarts (a restart begins above every
// id the previous run handed out, unless it made over a million events a second). A client that
// reconnects with Last-Event-ID N gets the kept events of its job with an id above N.
//
// What is kept, per job: every state change (up to kMaxEventsPerJob, oldest dropped first) and
// only the latest progress snapshot after the last state change (older progress is superseded).
// A finished job keeps its state changes only. An expired or deleted job's history goes.
//
// Producers: the job table's observer (state changes, under the table's lock; this class's
// mutex is a leaf) and the streams themselves, which sample progress while someone watches.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "renderer/render/render.h"
#include "server/storage/job_record.h"

namespace penumbra::server {

struct JobEvent {
  uint64_t id = 0;
  JobRecord record;
  std::optional<RenderProgress> progress;
  std::optional<std::size_t> queue_position;
  bool progress_only = false;  // a progress sample, not a state change
};

class JobEvents {
 public:
  static constexpr std::chrono::milliseconds kProgressInterval{250};
  static constexpr std::size_t kMaxEventsPerJob = 32;

  JobEvents();

  // A change of the job's record; returns its event id. A tombstone (deleted) forgets the job.
  uint64_t record_change(const JobRecord& record, std::optional<std::size_t> queue_position);
  // A progress snapshot of a running job: kept (and waiters woken) when the job's progress
  // moved and its last event is at least kProgressInterval old.
  void sample_progress(const JobRecord& record, const RenderProgress& progress);
  // The kept events of the job with an id above `after`, oldest first.
  std::vector<JobEvent> after(const std::string& job, uint64_t after) const;
  // The id of the job's latest kept event; a new one (with this record as its snapshot) when
  // nothing is kept for it (e.g. after a restart).
  uint64_t latest_id(const JobRecord& record, std::optional<std::size_t> queue_position);
  // Blocks until the job has an event above `after`, wake_all() or the deadline.
  void wait(const std::string& job, uint64_t after,
            std::chrono::steady_clock::time_point deadline) const;
  void forget(const std::string& job);
  void wake_all();

  // Streams open at once, capped (each holds a connection thread).
  bool try_open_stream(int max_streams);
  void close_stream();
  int open_streams() const;

 private:
  struct History {
    std::deque<JobEvent> events;
    std::chrono::steady_clock::time_point last_event_at;
  };
  uint64_t append(JobEvent event);  // under mutex_
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  uint64_t next_id_;
  uint64_t wake_generation_ = 0;
  std::unordered_map<std::string, History> jobs_;
  int open_streams_ = 0;
};

}  // namespace penumbra::server
