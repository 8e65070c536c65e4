#pragma once
// The jobs of a render farm, as an API node sees them: every answer is read from PostgreSQL,
// nothing is kept in this process but the event history of the streams it serves, so any number
// of API nodes answer for the same jobs (docs/scale-out.md). Rendering is FarmWorker's.
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <unordered_map>

#include "server/farm/pg_pool.h"
#include "server/jobs/job_backend.h"
#include "server/server_config.h"
#include "server/storage/file_result_store.h"

namespace penumbra::server {

// The channel a new or returned task is announced on (workers LISTEN) and the one job changes
// are announced on (API nodes' event streams LISTEN).
inline constexpr const char* kTaskChannel = "penumbra_tasks";
inline constexpr const char* kJobChannel = "penumbra_jobs";

// Where the worker rendering a job writes its progressive image (at heartbeats) on the shared
// volume, for GET /v1/jobs/{id}/result?preview=true on any API node; removed when the task ends.
std::string farm_preview_path(const std::string& data_dir, const std::string& job_id);

class FarmService final : public JobBackend {
 public:
  FarmService(const ServerConfig& config, PgPool& pool, FileResultStore& results,
              Metrics& metrics, AssetStore* assets);
  ~FarmService() override;

  // Starts the thread that turns job changes into events for the streams.
  void start();
  void begin_shutdown();
  void stop();

  SubmitOutcome submit(std::string_view body, const std::string& idempotency_key) override;
  std::optional<JobView> view(const std::string& id) const override;
  std::vector<JobView> list(std::optional<JobState> state, int64_t before_seq,
                            int limit) const override;
  std::vector<JobView> list_queued(std::optional<RunKey> after, int limit) const override;
  JobEvents& events() override { return events_; }
  void set_webhook_body(std::function<std::string(const JobRecord&)>) override {}
  bool stopping() const override { return stopping_.load(); }
  DeleteOutcome cancel_or_delete(const std::string& id, std::chrono::milliseconds wait) override;
  std::shared_ptr<const Image> preview(const std::string& id) const override;
  std::optional<StoredResult> open_result(const std::string& id, const std::string& format,
                                          std::optional<int> frame) const override;
  std::optional<JobRecord> wait_finished(
      const std::string& id, std::chrono::steady_clock::time_point deadline) const override;
  bool accepting() const override { return !stopping_.load(); }
  AssetStore* assets() const override { return assets_; }
  bool storage_ok() const override;
  Metrics::Gauges gauges() const override;
  double retry_after_for_queue() const override { return 5; }
  nlohmann::json workers() const override;
  bool frames_in_order() const override { return false; }

 private:
  // A split job's preview: the tiles' last previews (previews/<id>.w*.exr) placed in one frame.
  std::shared_ptr<const Image> tiles_preview(const std::string& id) const;
  JobView make_view(const PgRows& rows, int row, PgConnection& db) const;
  void event_loop();
  // Erases finished jobs older than --retention (rows, result files, asset folders); any API
  // node may do it: each expired row is deleted, and its files removed, by one of them.
  void reaper_loop();
  void expire_now();

  const ServerConfig config_;
  PgPool& pool_;
  FileResultStore& results_;
  Metrics& metrics_;
  AssetStore* assets_;
  JobEvents events_;
  std::atomic<bool> stopping_{false};
  std::thread event_thread_;
  std::thread reaper_;
};

}  // namespace penumbra::server
