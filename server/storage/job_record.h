#pragma once
// A render job as the store keeps it: plain data, no behaviour.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace penumbra::server {

enum class JobState { kQueued, kRunning, kSucceeded, kFailed, kCancelled, kDeleted };

const char* to_string(JobState s);
std::optional<JobState> job_state_from_string(const std::string& s);
inline bool is_finished(JobState s) {
  return s == JobState::kSucceeded || s == JobState::kFailed || s == JobState::kCancelled;
}

// Job ids are 24 lowercase hex digits (96 random bits), made by the server; anything else
// never reaches a store or the file system.
bool is_valid_job_id(std::string_view id);

struct JobRecord {
  std::string id;
  int64_t seq = 0;  // submission order; newest first in listings
  JobState state = JobState::kQueued;
  std::string idempotency_key;                             // "" = none
  double created_at = 0, started_at = 0, finished_at = 0;  // Unix seconds, 0 = not yet
  int attempts = 0;  // times a render started (a kill -9 mid-render leaves it counted)
  int width = 0, height = 0, spp = 0;
  uint64_t samples_total = 0;
  std::string stats_json;     // "" or a JSON object (render statistics)
  std::string error_json;     // "" or a JSON object (why it failed)
  std::string warnings_json;  // "" or a JSON array of {pointer, detail}
};

}  // namespace penumbra::server
