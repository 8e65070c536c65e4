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
  // An animation's frames (scene "animation": [frame_first, frame_last], both rendered) and how
  // many have finished; a still has frame_count() == 0.
  int frame_first = 0, frame_last = -1;
  int frames_done = 0;
  int frame_count() const { return frame_last >= frame_first ? frame_last - frame_first + 1 : 0; }
  std::string stats_json;     // "" or a JSON object (render statistics)
  std::string error_json;     // "" or a JSON object (why it failed)
  std::string warnings_json;  // "" or a JSON array of {pointer, detail}
  // Run order of queued jobs: higher first, submission order (seq) within a priority
  // (server/jobs/job_options.h has the bounds).
  int priority = 0;
  // The webhook told of the final state (url empty = none) and how its delivery went
  // (server/jobs/webhook_delivery.h). The secret is kept for signing and never shown.
  struct Notify {
    std::string url, secret;
    int attempts = 0;             // POSTs made so far
    int last_status = 0;          // HTTP status of the last attempt, 0 = no answer
    std::string last_error;       // "" after a success
    double last_attempt_at = 0;   // Unix seconds, 0 = none yet
    double next_attempt_at = 0;   // when the next retry is due, 0 = none planned
    double delivered_at = 0;      // a 2xx answer came
    double gave_up_at = 0;        // retries exhausted (--webhook-retry-for)
  } notify;
};

}  // namespace penumbra::server
