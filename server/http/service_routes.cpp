// GET /healthz, /readyz, /metrics, /v1/openapi.json, /v1/workers: the service itself, no job.
#include <httplib.h>

#include "api/embedded_documents.h"
#include "server/http/json_response.h"
#include "server/http/problem.h"
#include "server/http/route_context.h"

namespace penumbra::server {

void add_service_routes(httplib::Server& s, const RouteContext& c) {
  s.Get("/healthz", [](const httplib::Request&, httplib::Response& res) {
    send_json(res, 200, {{"status", "ok"}});
  });
  s.Get("/readyz", [&c](const httplib::Request& req, httplib::Response& res) {
    if (!c.ready || !c.jobs.accepting()) {
      Problem p = make_problem(503, "shutting-down", "Shutting down", "not accepting new jobs");
      p.retry_after_seconds = 5;
      return send_problem(res, req, p);
    }
    if (!c.jobs.storage_ok()) {
      Problem p = make_problem(503, "storage-low", "Storage nearly full",
                               "the data directory has less than --min-free-space available");
      p.retry_after_seconds = 30;
      return send_problem(res, req, p);
    }
    send_json(res, 200, {{"status", "ready"}});
  });
  s.Get("/metrics", [&c](const httplib::Request&, httplib::Response& res) {
    Metrics::Gauges g = c.jobs.gauges();
    g.ready = g.ready && c.ready;
    res.set_content(c.metrics.render_text(g), "text/plain; version=0.0.4; charset=utf-8");
  });
  // The render workers, their heartbeats and current tasks (farm: every worker process of the
  // store; one node: its own render threads).
  s.Get("/v1/workers", [&c](const httplib::Request&, httplib::Response& res) {
    send_json(res, 200, {{"workers", c.jobs.workers()}});
  });
  s.Get("/v1/openapi.json", [](const httplib::Request& req, httplib::Response& res) {
    const std::string* doc = api::embedded_document("openapi.json");
    if (!doc)
      return send_problem(res, req, status_problem(404, "no OpenAPI document was built in"));
    res.set_content(*doc, "application/json");
  });
}

}  // namespace penumbra::server
