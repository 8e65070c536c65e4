#include "renderer/io/exr_threads.h"

#include <OpenEXR/ImfThreading.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>

namespace penumbra {
namespace {
std::once_flag g_sized;
std::atomic<int> g_threads{0};
}  // namespace

int exr_threads() {
  std::call_once(g_sized, [] {
    const int n = int(std::clamp(std::thread::hardware_concurrency(), 1u, unsigned(kMaxExrThreads)));
    Imf::setGlobalThreadCount(n);
    g_threads = n;
  });
  return g_threads.load();
}

void set_exr_threads(int count) {
  exr_threads();  // the first sizing is done, so it cannot undo this one later
  count = std::clamp(count, 0, kMaxExrThreads);
  Imf::setGlobalThreadCount(count);
  g_threads = count;
}

}  // namespace penumbra
