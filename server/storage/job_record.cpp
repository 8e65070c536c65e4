#include "server/storage/job_record.h"

namespace penumbra::server {

bool is_valid_job_id(std::string_view id) {
  if (id.size() != 24) return false;
  for (char c : id)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

const char* to_string(JobState s) {
  switch (s) {
    case JobState::kQueued: return "queued";
    case JobState::kRunning: return "running";
    case JobState::kSucceeded: return "succeeded";
    case JobState::kFailed: return "failed";
    case JobState::kCancelled: return "cancelled";
    case JobState::kDeleted: return "deleted";
  }
  return "unknown";
}

std::optional<JobState> job_state_from_string(const std::string& s) {
  for (JobState st : {JobState::kQueued, JobState::kRunning, JobState::kSucceeded,
                      JobState::kFailed, JobState::kCancelled, JobState::kDeleted})
    if (s == to_string(st)) return st;
  return std::nullopt;
}

}  // namespace penumbra::server
