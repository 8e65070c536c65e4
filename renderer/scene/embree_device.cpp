#include "renderer/scene/embree_device.h"

#include <mutex>

#include "renderer/scene/scene.h"

namespace penumbra {
namespace {

std::mutex g_error_mutex;
std::string g_last_error;

// Embree calls this from C frames: record the message, never throw.
void on_embree_error(void*, RTCError code, const char* message) {
  std::lock_guard<std::mutex> lock(g_error_mutex);
  g_last_error = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

}  // namespace

RTCDevice embree_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice(nullptr);
    if (!d) throw SceneBuildError("cannot create the Embree device");
    rtcSetDeviceErrorFunction(d, on_embree_error, nullptr);
    return d;
  }();
  return device;
}

std::string take_embree_error() {
  std::lock_guard<std::mutex> lock(g_error_mutex);
  std::string e;
  e.swap(g_last_error);
  return e;
}

}  // namespace penumbra
