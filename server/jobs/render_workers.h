#pragma once
// The render worker threads. Each takes the next queued job, marks it running (on disk before
// the render starts), renders it, writes its images and records the outcome in the job table.
// They run on the service's own threads, never on HTTP threads.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/jobs/job_queue.h"
#include "server/jobs/job_table.h"
#include "server/jobs/render_task.h"
#include "server/jobs/store_writer.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/storage/job_store.h"
#include "server/storage/result_store.h"

namespace penumbra::server {

class RenderWorkers {
 public:
  RenderWorkers(const ServerConfig& config, JobQueue& queue, JobTable& table, StoreWriter& writer,
                JobStore& store, ResultStore& results, Metrics& metrics);
  ~RenderWorkers();  // joins; the queue must be closed before
  RenderWorkers(const RenderWorkers&) = delete;
  RenderWorkers& operator=(const RenderWorkers&) = delete;

  void start(int count);
  // No job starts from now on (a popped one stays queued for the restart); running renders are
  // stopped and requeued, except one that will be done within a few seconds.
  void begin_shutdown();
  // True once every worker has ended; false at the deadline.
  bool wait_stopped(std::chrono::steady_clock::time_point deadline);
  void join();
  // Seconds a job took lately (exponential average); 0 before the first one.
  double average_job_seconds() const { return average_job_seconds_.load(); }

 private:
  void loop();
  void run_job(const std::string& id);
  void finish_job(const std::string& id, const RenderOutcome& outcome, int threads);

  const ServerConfig& config_;
  JobQueue& queue_;
  JobTable& table_;
  StoreWriter& writer_;
  JobStore& store_;
  ResultStore& results_;
  Metrics& metrics_;
  std::atomic<bool> stopping_{false};
  std::atomic<double> average_job_seconds_{0};
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  int live_ = 0;  // under mutex_
  std::condition_variable done_cv_;
};

}  // namespace penumbra::server
