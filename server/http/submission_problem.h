#pragma once
// The problem document for a refused submission (POST /v1/jobs and POST /v1/render).
#include <optional>

#include "server/http/problem.h"
#include "server/jobs/job_service.h"

namespace penumbra::server {

// nullopt when the job exists (accepted or replayed).
std::optional<Problem> submission_problem(const SubmitOutcome& outcome);

}  // namespace penumbra::server
