#include "server/jobs/job_runtime.h"

namespace penumbra::server {

void JobRuntime::request_stop(StopReason reason) {
  StopReason expected = StopReason::kNone;
  stop_reason_.compare_exchange_strong(expected, reason);  // the first reason wins
  cancel_.store(true);
}

void JobRuntime::set_progress(const RenderProgress& p) {
  std::lock_guard lock(mutex_);
  progress_ = p;
}

RenderProgress JobRuntime::progress() const {
  std::lock_guard lock(mutex_);
  return progress_;
}

void JobRuntime::set_preview(const Image& image) {
  auto copy = std::make_shared<const Image>(image);  // copied outside the lock
  std::lock_guard lock(mutex_);
  preview_ = std::move(copy);
}

std::shared_ptr<const Image> JobRuntime::preview() const {
  std::lock_guard lock(mutex_);
  return preview_;
}

void JobRuntime::clear_preview() {
  std::lock_guard lock(mutex_);
  preview_ = nullptr;
}

}  // namespace penumbra::server
