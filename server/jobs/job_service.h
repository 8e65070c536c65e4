#pragma once
// The jobs: submission (validate, idempotency, capacity, durable commit), the FIFO queue, the
// render workers on their own threads, cancellation, deletion, expiry and graceful shutdown.
// HTTP handlers call this and only translate its answers.
//
// Locking (why a status poll never waits on a disk): the state of every job is in memory
// (JobTable, one short mutex). Changes go to the store from one writer thread (StoreWriter);
// only the callers that must not answer before a change is durable wait for it (submit,
// cancel, delete, and a worker before it starts a render), and they wait with no lock held.
// Result files are written and removed with no lock held. view() and list() take the table's
// mutex, the queue's and a running job's progress mutex, each for a copy, never anything else.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "api/job_submission.h"
#include "api/scene_loader.h"
#include "server/jobs/job_backend.h"
#include "server/jobs/job_events.h"
#include "server/jobs/job_queue.h"
#include "server/jobs/job_table.h"
#include "server/jobs/render_task.h"
#include "server/jobs/render_workers.h"
#include "server/jobs/store_writer.h"
#include "server/jobs/webhook_sender.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/storage/asset_store.h"
#include "server/storage/job_record.h"
#include "server/storage/job_store.h"
#include "server/storage/result_store.h"

namespace penumbra::server {

class JobService final : public JobBackend {
 public:
  // `assets` (may be null: then jobs cannot name files) holds the uploaded files jobs name.
  JobService(const ServerConfig& config, JobStore& store, ResultStore& results, Metrics& metrics,
             AssetStore* assets = nullptr);
  ~JobService();

  // Loads the jobs from the store (interrupted ones run again) and starts the threads.
  void start();
  SubmitOutcome submit(std::string_view body, const std::string& idempotency_key) override;
  std::optional<JobView> view(const std::string& id) const override;
  std::vector<JobView> list(std::optional<JobState> state, int64_t before_seq, int limit) const override;
  std::vector<JobView> list_queued(std::optional<RunKey> after, int limit) const override;
  // State changes and progress for GET /v1/jobs/{id}/events.
  JobEvents& events() override { return events_; }
  // The JSON a webhook POSTs for a job (the HTTP layer's job document); set before start().
  void set_webhook_body(std::function<std::string(const JobRecord&)> body) override {
    webhook_body_ = std::move(body);
  }
  bool stopping() const override { return stopping_.load(); }
  // Cancels a queued/running job, deletes a finished one. Waits up to `wait` for a running
  // render to stop.
  DeleteOutcome cancel_or_delete(const std::string& id, std::chrono::milliseconds wait) override;
  std::shared_ptr<const Image> preview(const std::string& id) const override;
  std::optional<StoredResult> open_result(const std::string& id, const std::string& format,
                                          std::optional<int> frame) const override;
  // Blocks until the job is finished, the deadline passes or shutdown begins.
  std::optional<JobRecord> wait_finished(const std::string& id,
                                         std::chrono::steady_clock::time_point deadline) const override;

  bool accepting() const override { return accepting_.load(); }
  // The asset store (null when the server keeps none).
  AssetStore* assets() const override { return assets_; }
  // One node: its own render threads are its only worker.
  nlohmann::json workers() const override;
  bool frames_in_order() const override { return true; }
  // False while the data directory has less than --min-free-space available (/readyz).
  bool storage_ok() const override;
  // Stops taking jobs; running renders are put back in the queue, except one that will be done
  // within a few seconds, which is finished.
  void begin_shutdown();
  // Joins the threads and writes every pending change; true if the threads all ended before
  // the deadline.
  bool stop(std::chrono::steady_clock::time_point deadline);
  // Removes finished jobs older than the retention now (the reaper thread does it periodically).
  void expire_now();

  Metrics::Gauges gauges() const override;
  double retry_after_for_queue() const override;
  // The worst case of every queued and running job's images: space already promised.
  std::uint64_t reserved_bytes() const;

 private:
  void reaper_loop();
  void observe(const JobEntry& entry);  // the job table's observer (under its lock)
  // Queued or running: its asset folder is still needed.
  bool job_is_live(const std::string& id) const;
  JobView make_view(JobEntry entry) const;

  const ServerConfig config_;
  JobStore& store_;  // read here (scenes); written only through writer_
  ResultStore& results_;
  Metrics& metrics_;
  AssetStore* assets_;
  StoreWriter writer_;
  JobTable table_;
  JobQueue queue_;
  RenderWorkers workers_;
  JobEvents events_;
  WebhookSender webhooks_;
  std::function<std::string(const JobRecord&)> webhook_body_;

  std::mutex submit_mutex_;  // idempotency check + capacity check + commit + enqueue as one step
  int64_t last_seq_ = 0;     // under submit_mutex_

  std::atomic<bool> accepting_{true};
  std::atomic<bool> stopping_{false};
  std::thread reaper_;
  std::mutex reaper_mutex_;
  std::condition_variable reaper_cv_;
};

}  // namespace penumbra::server
