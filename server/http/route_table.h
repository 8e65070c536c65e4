#pragma once
// The API's paths: the patterns handlers are registered with, and the template of a request
// path (for metric labels and 405 answers), found without std::regex.
#include <string>
#include <string_view>
#include <vector>

namespace penumbra::server {

// cpp-httplib 0.11 has no path parameters: routes with an id are registered as regexes
// (compiled once, at registration).
inline const std::string kJobRoute = "/v1/jobs/([0-9a-f]{24})";
inline const std::string kResultRoute = kJobRoute + "/result";
inline const std::string kEventsRoute = kJobRoute + "/events";
inline const std::string kFramesArchiveRoute = kJobRoute + "/frames\\.tar";
// Any last segment: a malformed hash gets a 400 naming it rather than a bare 404.
inline const std::string kAssetRoute = "/v1/assets/([^/]+)";

// A dashboard file's name as /dashboard/{file} serves it: letters, digits, '_', '-', then one
// dot and a lowercase extension (the pattern of kDashboardRoute).
bool is_dashboard_file_name(std::string_view name);
inline const std::string kDashboardRoute = R"(/dashboard/([A-Za-z0-9_-]+\.[a-z]+))";

// Paths served without a token: /healthz and /readyz (orchestrators probe them without
// credentials; they tell only whether the node is alive and ready) and the
// dashboard's static files (/, /dashboard/...), which hold no data.
bool is_public_route(const std::string& path);
// The route template of a path ("/v1/jobs/{id}"), or "other": a bounded set of labels.
std::string route_template(const std::string& path);
// The methods a route template answers (for Allow on a 405).
std::vector<std::string> allowed_methods(const std::string& route);

}  // namespace penumbra::server
