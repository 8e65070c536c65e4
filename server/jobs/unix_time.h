#pragma once
// The wall-clock time job records carry (created_at, started_at, finished_at).
#include <chrono>

namespace penumbra::server {

inline double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace penumbra::server
