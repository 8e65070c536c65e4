#pragma once
// What HTTP threads may read about a running job while a worker renders it: progress, the
// latest progressive image, and the stop request they may make.
#include <atomic>
#include <memory>
#include <mutex>

#include "renderer/core/image.h"
#include "renderer/render/render.h"

namespace penumbra::server {

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
  // No preview until the next pass (an animation's next frame starts: the last one's image is
  // not this frame's).
  void clear_preview();

 private:
  std::atomic<bool> cancel_{false};
  std::atomic<StopReason> stop_reason_{StopReason::kNone};
  mutable std::mutex mutex_;
  RenderProgress progress_;
  std::shared_ptr<const Image> preview_;
};

}  // namespace penumbra::server
