#pragma once
// What every route group's handlers reach: they translate HTTP to JobBackend calls (jobs/job_backend.h) and back.
#include <atomic>

#include "server/jobs/job_backend.h"
#include "server/metrics.h"
#include "server/server_config.h"

namespace httplib {
class Server;
}

namespace penumbra::server {

struct RouteContext {
  const ServerConfig& config;
  JobBackend& jobs;
  Metrics& metrics;
  const std::atomic<bool>& ready;  // false once shutdown has begun
};

// One function per route group, each in its own file.
void add_service_routes(httplib::Server& server,
                        const RouteContext& context);  // health, metrics, OpenAPI
void add_job_routes(httplib::Server& server,
                    const RouteContext& context);  // /v1/jobs, /v1/jobs/{id}
void add_result_routes(httplib::Server& server,
                       const RouteContext& context);  // /v1/jobs/{id}/result
void add_render_routes(httplib::Server& server, const RouteContext& context);  // /v1/render
void add_asset_routes(httplib::Server& server, const RouteContext& context);   // /v1/assets
void add_dashboard_routes(httplib::Server& server,
                          const RouteContext& context);  // /, /dashboard/{file}
void add_event_routes(httplib::Server& server,
                      const RouteContext& context);  // /v1/jobs/{id}/events

}  // namespace penumbra::server
