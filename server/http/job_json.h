#pragma once
// The JSON shape of a job in API answers (documented in api/openapi.json, schema "Job").
#include <nlohmann/json.hpp>
#include <string>

#include "server/jobs/job_service.h"

namespace penumbra::server {

nlohmann::ordered_json job_json(const JobView& job);
// The "notify" member: the webhook's URL and delivery status (never its secret).
nlohmann::ordered_json notify_json(const JobRecord::Notify& notify);
// The body a webhook POSTs: the finished job's document, stable across retries.
std::string webhook_body(const JobRecord& record);
std::string job_path(const std::string& id);
// Retry-After for an unfinished job: about when something will have changed.
double retry_after_seconds(const JobView& job);
// RFC 3339 UTC with milliseconds, e.g. 2024-05-01T12:00:00.123Z.
std::string rfc3339(double unix_seconds);

}  // namespace penumbra::server
