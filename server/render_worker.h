#pragma once
// Runs one job: scene JSON -> validated request -> Embree scene -> progressive render.
// Called on the service's own worker threads, never on HTTP threads.
#include <atomic>
#include <memory>
#include <mutex>
#include <string>

#include "api/scene_loader.h"
#include "renderer/core/image.h"
#include "renderer/render/render.h"

namespace penumbra::server {

// What HTTP threads may read about a running job while a worker renders it.
class JobRuntime {
 public:
  enum class StopReason { kNone, kUserCancel, kShutdown };

  void request_stop(StopReason reason);
  StopReason stop_reason() const { return stop_reason_.load(); }
  const std::atomic<bool>* cancel_flag() const { return &cancel_; }

  void set_progress(const RenderProgress& p);
  RenderProgress progress() const;
  void set_preview(const Image& image);
  std::shared_ptr<const Image> preview() const;

 private:
  std::atomic<bool> cancel_{false};
  std::atomic<StopReason> stop_reason_{StopReason::kNone};
  mutable std::mutex mutex_;
  RenderProgress progress_;
  std::shared_ptr<const Image> preview_;
};

struct RenderJobOptions {
  api::Limits limits;
  int threads = 0;                 // render threads for this job
  double max_render_seconds = 0;   // the server's budget per job; 0 = none
};

struct RenderOutcome {
  enum class Kind { kSucceeded, kFailed, kStopped };
  Kind kind = Kind::kFailed;
  Image image;
  RenderStats stats;
  RenderSettings settings;
  double build_seconds = 0;
  std::string error;  // when failed
};

RenderOutcome run_render_job(const std::string& scene_json, const RenderJobOptions& options,
                             JobRuntime& runtime);

}  // namespace penumbra::server
