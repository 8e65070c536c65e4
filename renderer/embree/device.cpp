#include "renderer/embree/device.h"

#include "renderer/core/errors.h"

namespace penumbra {
namespace {

thread_local EmbreeErrorScope* t_scope = nullptr;

std::string describe(RTCError code, const char* message) {
  return "Embree error " + std::to_string(int(code)) + (message && *message ? ": " : "") +
         (message ? message : "");
}

// Embree calls this from C frames: record the message, never throw.
void on_embree_error(void*, RTCError code, const char* message) { record_embree_error(code, message); }

}  // namespace

void record_embree_error(RTCError code, const char* message) {
  if (t_scope && t_scope->first_.empty()) t_scope->first_ = describe(code, message);
}

RTCDevice embree_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice(nullptr);
    if (!d) throw SceneBuildError("cannot create the Embree device");
    rtcSetDeviceErrorFunction(d, on_embree_error, nullptr);
    return d;
  }();
  return device;
}

EmbreeErrorScope::EmbreeErrorScope() : outer_(t_scope) {
  // Clear the code a failed call before this scope may have left on this thread.
  rtcGetDeviceError(embree_device());
  t_scope = this;
}

EmbreeErrorScope::~EmbreeErrorScope() { t_scope = outer_; }

std::string EmbreeErrorScope::first_error() {
  const RTCError code = rtcGetDeviceError(embree_device());
  if (first_.empty() && code != RTC_ERROR_NONE) first_ = describe(code, nullptr);
  return first_;
}

}  // namespace penumbra
