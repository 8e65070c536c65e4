#include "server/storage/job_record.h"

#include <array>
#include <utility>

namespace penumbra::server {

bool is_valid_job_id(std::string_view id) {
  if (id.size() != 24) return false;
  for (char c : id)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

namespace {

// Stored in the job store, and shown in the API (all but "deleted", a tombstone never shown).
constexpr std::array<std::pair<JobState, const char*>, 6> kStateNames = {{
    {JobState::kQueued, "queued"},
    {JobState::kRunning, "running"},
    {JobState::kSucceeded, "succeeded"},
    {JobState::kFailed, "failed"},
    {JobState::kCancelled, "cancelled"},
    {JobState::kDeleted, "deleted"},
}};

}  // namespace

const char* to_string(JobState s) {
  for (const auto& [state, name] : kStateNames)
    if (state == s) return name;
  return "unknown";
}

std::optional<JobState> job_state_from_string(const std::string& s) {
  for (const auto& [state, name] : kStateNames)
    if (s == name) return state;
  return std::nullopt;
}

}  // namespace penumbra::server
