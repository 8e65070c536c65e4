#include "server/http/route_table.h"

#include <cctype>

#include "api/job_submission.h"
#include "server/storage/job_record.h"

namespace penumbra::server {

using api::is_sha256_hex;

bool is_dashboard_file_name(std::string_view name) {
  const std::size_t dot = name.rfind('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 == name.size()) return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool ok = i < dot ? (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')
                            : (c >= 'a' && c <= 'z');
    if (!ok) return false;
  }
  return true;
}

bool is_public_route(const std::string& path) {
  return path == "/healthz" || path == "/readyz" || path == "/" || path.rfind("/dashboard/", 0) == 0;
}

std::string route_template(const std::string& path) {
  if (path == "/") return "/";
  if (path.rfind("/dashboard/", 0) == 0)
    return is_dashboard_file_name(path.substr(11)) ? "/dashboard/{file}" : "other";
  for (const char* fixed :
       {"/healthz", "/readyz", "/metrics", "/v1/openapi.json", "/v1/jobs", "/v1/render",
        "/v1/assets/missing", "/v1/workers"})
    if (path == fixed) return fixed;
  constexpr std::string_view kAssets = "/v1/assets/";
  if (path.compare(0, kAssets.size(), kAssets) == 0 && path.size() == kAssets.size() + 64 &&
      is_sha256_hex(std::string_view(path).substr(kAssets.size())))
    return "/v1/assets/{sha256}";
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
  if (rest == "/frames.tar") return "/v1/jobs/{id}/frames.tar";
  return "other";
}

std::vector<std::string> allowed_methods(const std::string& route) {
  if (route == "/v1/jobs") return {"GET", "HEAD", "POST"};
  if (route == "/v1/jobs/{id}") return {"GET", "HEAD", "DELETE"};
  if (route == "/v1/render") return {"POST"};
  if (route == "/v1/assets/missing") return {"POST"};
  if (route == "/v1/assets/{sha256}") return {"GET", "HEAD", "PUT"};
  return {"GET", "HEAD"};
}

}  // namespace penumbra::server
