#pragma once
// What the HTTP routes call: the jobs of the service, wherever their state lives. Two backends:
// JobService (one node, state in memory, SQLite underneath; the default) and FarmService
// (server/farm/farm_service.h: stateless API nodes and workers over PostgreSQL). Handlers only
// translate these answers to HTTP; nothing here names a table, a queue or a thread.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/diagnostics.h"
#include "renderer/core/image.h"
#include "renderer/render/render.h"
#include "server/jobs/job_events.h"
#include "server/metrics.h"
#include "server/storage/asset_store.h"
#include "server/storage/job_record.h"
#include "server/storage/result_store.h"

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
    kNoSpace,       // the data directory cannot hold the job's worst case (507)
    kStoreFailed,   // the job could not be stored for another reason (503)
  };
  Kind kind = Kind::kAccepted;
  JobRecord record;
  std::vector<api::Diagnostic> errors;
  std::vector<api::Diagnostic> warnings;
  double retry_after_seconds = 0;
  std::uint64_t bytes_needed = 0;     // kNoSpace
  std::uint64_t bytes_available = 0;  // kNoSpace
};

struct JobView {
  JobRecord record;
  std::optional<RenderProgress> progress;     // while running
  std::optional<std::size_t> queue_position;  // while queued
  bool stop_requested = false;
  // An animation whose frames render one at a time in order (one node): the frame under way is
  // frame_first + frames_done. A farm renders several at once, in any order: nullopt.
  std::optional<int> current_frame;
};

// The frame under way of a running animation whose frames render in order (see JobView).
inline std::optional<int> in_order_current_frame(const JobRecord& r) {
  if (r.state != JobState::kRunning || r.frames_done >= r.frame_count()) return std::nullopt;
  return r.frame_first + r.frames_done;
}

enum class DeleteOutcome {
  kNotFound,    // never existed (or expired)
  kCancelled,   // was queued or running, now cancelled
  kCancelling,  // running; the render has been told to stop but has not yet
  kDeleted,     // was finished; record and result removed
};

class JobBackend {
 public:
  virtual ~JobBackend() = default;

  virtual SubmitOutcome submit(std::string_view body, const std::string& idempotency_key) = 0;
  virtual std::optional<JobView> view(const std::string& id) const = 0;
  // Newest first; seq < before_seq (0 = from the newest); tombstones never.
  virtual std::vector<JobView> list(std::optional<JobState> state, int64_t before_seq,
                                    int limit) const = 0;
  // Queued jobs in run order (priority, then seq), starting after the job with run key
  // `after` (nullopt: from the first to run).
  struct RunKey {
    int priority = 0;
    int64_t seq = 0;
  };
  virtual std::vector<JobView> list_queued(std::optional<RunKey> after, int limit) const = 0;
  // State changes and progress for GET /v1/jobs/{id}/events.
  virtual JobEvents& events() = 0;
  // The JSON a webhook POSTs for a job (the HTTP layer's job document); set before start().
  virtual void set_webhook_body(std::function<std::string(const JobRecord&)> body) = 0;
  virtual bool stopping() const = 0;
  // Cancels a queued/running job, deletes a finished one. Waits up to `wait` for a running
  // render to stop.
  virtual DeleteOutcome cancel_or_delete(const std::string& id, std::chrono::milliseconds wait) = 0;
  virtual std::shared_ptr<const Image> preview(const std::string& id) const = 0;
  // `frame`: which frame of an animation (nullopt: a still's image; for an animation, its
  // first frame). nullopt when there is no such result (yet).
  virtual std::optional<StoredResult> open_result(const std::string& id, const std::string& format,
                                                  std::optional<int> frame) const = 0;
  // Blocks until the job is finished, the deadline passes or shutdown begins.
  virtual std::optional<JobRecord> wait_finished(
      const std::string& id, std::chrono::steady_clock::time_point deadline) const = 0;
  virtual bool accepting() const = 0;
  // The asset store (null when the server keeps none).
  virtual AssetStore* assets() const = 0;
  // False while the service cannot take jobs for want of storage (/readyz): the data directory
  // is nearly full, or (farm) the database does not answer.
  virtual bool storage_ok() const = 0;
  virtual Metrics::Gauges gauges() const = 0;
  virtual double retry_after_for_queue() const = 0;
  // GET /v1/workers: the render workers, their heartbeats and current tasks (a JSON array).
  virtual nlohmann::json workers() const = 0;
  // True when an animation's frames render one at a time, in order (one node); a farm renders
  // them at once on several workers.
  virtual bool frames_in_order() const = 0;
};

}  // namespace penumbra::server
