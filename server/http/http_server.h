#pragma once
// The HTTP service on cpp-httplib: its settings, the guard before routing, problem documents
// for the library's own errors, the exception handler, the access log and metrics; the routes
// themselves are in one file per group (route_context.h). Renders never run on HTTP threads
// (JobService owns the workers), so polls are answered at once.
#include <atomic>
#include <memory>

#include "server/http/auth.h"
#include "server/http/guarded_server.h"
#include "server/http/route_context.h"
#include "server/jobs/job_service.h"
#include "server/metrics.h"
#include "server/server_config.h"

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace penumbra::server {

class HttpServer {
 public:
  HttpServer(const ServerConfig& config, JobBackend& jobs, Metrics& metrics);
  ~HttpServer();
  // Binds host:port (port 0 = ephemeral); returns the bound port, or -1.
  int bind();
  // After bind(): whether the address actually bound is a loopback address.
  bool bound_to_loopback() const;
  // Serves until stop(); blocks.
  bool listen();
  void stop();
  // /readyz answers 503 from now on (shutdown has begun); the port stays open.
  void set_ready(bool ready) { ready_ = ready; }

 private:
  void install_handlers();
  // For Expect: 100-continue on PUT /v1/assets/{sha256}: answers 200 when the hash is stored.
  bool answer_known_asset(const httplib::Request& req, httplib::Response& res);
  const ServerConfig config_;
  Metrics& metrics_;
  BearerAuth auth_;
  std::atomic<bool> ready_{true};
  RouteContext context_;
  std::unique_ptr<GuardedServer> server_;
};

}  // namespace penumbra::server
