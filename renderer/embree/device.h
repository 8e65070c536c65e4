#pragma once
// The process-wide Embree device (the one piece of global state the renderer keeps) and the
// recording of its errors per scene build.
#include <embree3/rtcore.h>

#include <string>

namespace penumbra {

// Created on first use; thread-safe. Throws SceneBuildError if Embree cannot start.
RTCDevice embree_device();

// Collects the first error Embree reports on this thread while the scope is alive. Embree keeps
// its error state per thread and device and calls the error callback on the thread whose API
// call failed (a commit's build tasks report through the committing thread), so concurrent
// scene builds on different threads never see each other's errors. Scopes nest: the innermost
// one records.
class EmbreeErrorScope {
 public:
  EmbreeErrorScope();
  ~EmbreeErrorScope();
  EmbreeErrorScope(const EmbreeErrorScope&) = delete;
  EmbreeErrorScope& operator=(const EmbreeErrorScope&) = delete;

  // The first error reported in this scope ("" if none); also picks up an error code Embree
  // stored without calling back.
  std::string first_error();

 private:
  friend void record_embree_error(RTCError code, const char* message);
  EmbreeErrorScope* outer_;
  std::string first_;
};

// The device's error callback: hands an error to this thread's innermost scope, if any.
void record_embree_error(RTCError code, const char* message);

}  // namespace penumbra
