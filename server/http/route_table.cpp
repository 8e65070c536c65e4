#include "server/http/route_table.h"

#include "server/storage/job_record.h"

namespace penumbra::server {

std::string route_template(const std::string& path) {
  for (const char* fixed :
       {"/healthz", "/readyz", "/metrics", "/v1/openapi.json", "/v1/jobs", "/v1/render"})
    if (path == fixed) return fixed;
  constexpr std::string_view kJobs = "/v1/jobs/";
  constexpr std::string_view kResult = "/result";
  constexpr std::size_t kIdLength = 24;
  if (path.compare(0, kJobs.size(), kJobs) != 0 || path.size() < kJobs.size() + kIdLength)
    return "other";
  if (!is_valid_job_id(path.substr(kJobs.size(), kIdLength))) return "other";
  const std::string_view rest = std::string_view(path).substr(kJobs.size() + kIdLength);
  if (rest.empty()) return "/v1/jobs/{id}";
  if (rest == kResult) return "/v1/jobs/{id}/result";
  if (rest == "/events") return "/v1/jobs/{id}/events";
  return "other";
}

std::vector<std::string> allowed_methods(const std::string& route) {
  if (route == "/v1/jobs") return {"GET", "HEAD", "POST"};
  if (route == "/v1/jobs/{id}") return {"GET", "HEAD", "DELETE"};
  if (route == "/v1/render") return {"POST"};
  return {"GET", "HEAD"};
}

}  // namespace penumbra::server
