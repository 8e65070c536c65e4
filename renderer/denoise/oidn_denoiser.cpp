#include "renderer/denoise/oidn_denoiser.h"

#include <dlfcn.h>

#include <cmath>
#include <cstdlib>
#include <mutex>

#include "renderer/io/executable_dir.h"

namespace penumbra {
namespace {

// The part of OIDN 2's C API used here, declared from its documentation (doc/api.md): opaque
// handles, and the values of the enums passed (OIDN_DEVICE_TYPE_CPU = 1, OIDN_FORMAT_FLOAT3 = 3,
// OIDN_ERROR_NONE = 0).
using Device = void*;
using Filter = void*;
constexpr int kDeviceCpu = 1;
constexpr int kFormatFloat3 = 3;

struct Api {
  Device (*new_device)(int) = nullptr;
  void (*commit_device)(Device) = nullptr;
  void (*release_device)(Device) = nullptr;
  int (*device_error)(Device, const char**) = nullptr;
  Filter (*new_filter)(Device, const char*) = nullptr;
  void (*set_image)(Filter, const char*, void*, int, size_t, size_t, size_t, size_t, size_t) = nullptr;
  void (*set_bool)(Filter, const char*, bool) = nullptr;
  void (*commit_filter)(Filter) = nullptr;
  void (*execute_filter)(Filter) = nullptr;
  void (*release_filter)(Filter) = nullptr;
  std::string error;  // why it is not loaded ("" = loaded)
};

template <typename F>
bool bind(void* lib, const char* name, F* out) {
  *out = reinterpret_cast<F>(::dlsym(lib, name));
  return *out != nullptr;
}

Api load() {
  Api api;
  std::string dir;
  if (const char* env = std::getenv("PENUMBRA_OIDN_DIR"); env && *env) {
    dir = env;
  } else {
    const std::string exe = executable_dir();
    dir = (exe.empty() ? std::string(".") : exe) + "/../lib/penumbra/oidn";
  }
  // The core first, by path and globally: the API library names it by soname, and the wheel's
  // RPATH ($ORIGIN/../lib) only finds it in a folder called lib. The CPU device module is
  // loaded by the core from its own folder. OIDN's CPU device uses Debian's libtbb12 (the
  // wheel's own TBB is not installed: it would replace the TBB under Embree).
  for (const char* name : {"libOpenImageDenoise_core.so.2.5.1", "libOpenImageDenoise.so.2"}) {
    const std::string path = dir + "/" + name;
    void* lib = ::dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
    if (!lib) {
      const char* why = ::dlerror();
      api.error = "Open Image Denoise is not installed (scripts/install-oidn.sh): " +
                  std::string(why ? why : path);
      return api;
    }
    if (std::string(name) != "libOpenImageDenoise.so.2") continue;
    const bool ok = bind(lib, "oidnNewDevice", &api.new_device) &&
                    bind(lib, "oidnCommitDevice", &api.commit_device) &&
                    bind(lib, "oidnReleaseDevice", &api.release_device) &&
                    bind(lib, "oidnGetDeviceError", &api.device_error) &&
                    bind(lib, "oidnNewFilter", &api.new_filter) &&
                    bind(lib, "oidnSetSharedFilterImage", &api.set_image) &&
                    bind(lib, "oidnSetFilterBool", &api.set_bool) &&
                    bind(lib, "oidnCommitFilter", &api.commit_filter) &&
                    bind(lib, "oidnExecuteFilter", &api.execute_filter) &&
                    bind(lib, "oidnReleaseFilter", &api.release_filter);
    if (!ok) {
      api = Api{};
      api.error = path + ": not Open Image Denoise 2";
    }
  }
  return api;
}

const Api& api() {
  static const Api a = load();
  return a;
}

// The device's pending error, or "".
std::string device_error(const Api& a, Device device) {
  const char* message = nullptr;
  if (a.device_error(device, &message) == 0) return "";
  return std::string("Open Image Denoise: ") + (message ? message : "unknown error");
}

}  // namespace

bool denoiser_available(std::string* why) {
  const Api& a = api();
  if (why) *why = a.error;
  return a.error.empty();
}

std::optional<std::vector<float>> denoise(const DenoiseInput& in, std::string* error) {
  const Api& a = api();
  if (!a.error.empty()) {
    *error = a.error;
    return std::nullopt;
  }
  if (in.width <= 0 || in.height <= 0 || !in.color) {
    *error = "nothing to denoise";
    return std::nullopt;
  }
  // OIDN documents finite inputs; the renderer's images are (never NaN/Inf), and an albedo
  // outside [0, 1] or an unnormalised normal is the caller's bug, clamped here all the same.
  const size_t n = size_t(in.width) * size_t(in.height) * 3;
  std::vector<float> color(in.color, in.color + n), albedo, normal, out(n, 0.f);
  for (float& v : color) v = std::isfinite(v) ? std::max(v, 0.f) : 0.f;
  if (in.albedo) {
    albedo.assign(in.albedo, in.albedo + n);
    for (float& v : albedo) v = std::isfinite(v) ? std::min(std::max(v, 0.f), 1.f) : 0.f;
  }
  if (in.normal && in.albedo) {
    normal.assign(in.normal, in.normal + n);
    for (float& v : normal) v = std::isfinite(v) ? std::min(std::max(v, -1.f), 1.f) : 0.f;
  }
  // One device per call: OIDN serialises the work of a device; jobs run side by side.
  Device device = a.new_device(kDeviceCpu);
  if (!device) {
    *error = device_error(a, nullptr);
    if (error->empty()) *error = "Open Image Denoise: no CPU device";
    return std::nullopt;
  }
  a.commit_device(device);
  std::string failure = device_error(a, device);
  Filter filter = failure.empty() ? a.new_filter(device, "RT") : nullptr;
  if (filter) {
    const size_t w = size_t(in.width), h = size_t(in.height);
    a.set_image(filter, "color", color.data(), kFormatFloat3, w, h, 0, 0, 0);
    if (!albedo.empty()) a.set_image(filter, "albedo", albedo.data(), kFormatFloat3, w, h, 0, 0, 0);
    if (!normal.empty()) a.set_image(filter, "normal", normal.data(), kFormatFloat3, w, h, 0, 0, 0);
    a.set_image(filter, "output", out.data(), kFormatFloat3, w, h, 0, 0, 0);
    a.set_bool(filter, "hdr", true);
    a.commit_filter(filter);
    a.execute_filter(filter);
    failure = device_error(a, device);
    a.release_filter(filter);
  } else if (failure.empty()) {
    failure = device_error(a, device);
  }
  a.release_device(device);
  if (!failure.empty()) {
    *error = failure;
    return std::nullopt;
  }
  for (float& v : out) v = std::isfinite(v) ? std::max(v, 0.f) : 0.f;
  return out;
}

}  // namespace penumbra
