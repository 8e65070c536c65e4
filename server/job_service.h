#pragma once
// The jobs: submission (validate, idempotency, capacity, durable commit), the FIFO queue, the
// render workers on their own threads, cancellation, deletion, expiry and graceful shutdown.
// HTTP handlers call this and only translate its answers.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "api/scene_loader.h"
#include "server/job_queue.h"
#include "server/job_record.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/render_worker.h"
#include "server/result_files.h"
#include "server/server_config.h"

namespace penumbra::server {

struct SubmitOutcome {
  enum class Kind {
    kAccepted,      // new job, committed
    kReplayed,      // same idempotency key and scene: the existing job
    kSyntax,        // not JSON (400)
    kInvalid,       // not a valid scene (422)
    kKeyReused,     // idempotency key used for another scene (422)
    kQueueFull,     // 429
    kNotAccepting,  // shutting down (503)
  };
  Kind kind = Kind::kAccepted;
  JobRecord record;
  std::vector<api::Diagnostic> errors;
  std::vector<api::Diagnostic> warnings;
  double retry_after_seconds = 0;
};

struct JobView {
  JobRecord record;
  std::optional<RenderProgress> progress;        // while running
  std::optional<std::size_t> queue_position;     // while queued
  bool stop_requested = false;
};

enum class DeleteOutcome {
  kNotFound,     // never existed (or expired)
  kCancelled,    // was queued or running, now cancelled
  kCancelling,   // running; the render has been told to stop but has not yet
  kDeleted,      // was finished; record and result removed
};

class JobService {
 public:
  JobService(const ServerConfig& config, JobStore& store, ResultFiles& files, Metrics& metrics);
  ~JobService();

  // Recovers the queue from the store (interrupted jobs run again) and starts the threads.
  void start();
  SubmitOutcome submit(std::string_view body, const std::string& idempotency_key);
  std::optional<JobView> view(const std::string& id);
  std::vector<JobView> list(std::optional<JobState> state, int64_t before_seq, int limit);
  // Cancels a queued/running job, deletes a finished one. Waits up to `wait` for a running
  // render to stop.
  DeleteOutcome cancel_or_delete(const std::string& id, std::chrono::milliseconds wait);
  std::shared_ptr<const Image> preview(const std::string& id);
  // Blocks until the job is finished, the deadline passes or shutdown begins.
  std::optional<JobRecord> wait_finished(const std::string& id,
                                         std::chrono::steady_clock::time_point deadline);

  std::string result_path(const std::string& id, const std::string& extension) const {
    return files_.path(id, extension);
  }
  bool accepting() const { return accepting_.load(); }
  // Stops taking jobs; running renders are put back in the queue, except one that will be done
  // within a few seconds, which is finished.
  void begin_shutdown();
  // Joins the threads; true if they all ended before the deadline.
  bool stop(std::chrono::steady_clock::time_point deadline);

  Metrics::Gauges gauges();
  double retry_after_for_queue() const;

 private:
  void worker_loop();
  void run_job(const std::string& id, const std::shared_ptr<JobRuntime>& runtime);
  void reaper_loop();
  void expire_now();
  std::string new_job_id();

  const ServerConfig config_;
  JobStore& store_;
  ResultFiles& files_;
  Metrics& metrics_;
  JobQueue queue_;

  std::mutex submit_mutex_;  // capacity check + commit + enqueue happen as one step
  mutable std::mutex mutex_;  // running_, finished_cv_, average
  std::condition_variable finished_cv_;
  std::map<std::string, std::shared_ptr<JobRuntime>> running_;
  double average_job_seconds_ = 0;

  std::atomic<bool> accepting_{true};
  std::atomic<bool> stopping_{false};
  std::vector<std::thread> workers_;
  std::atomic<int> live_workers_{0};
  std::condition_variable workers_done_cv_;
  std::thread reaper_;
  std::mutex reaper_mutex_;
  std::condition_variable reaper_cv_;
};

}  // namespace penumbra::server
