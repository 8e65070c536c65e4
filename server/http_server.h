#pragma once
// Routes of the HTTP API on cpp-httplib: thin handlers translating HTTP to JobService calls.
// Renders never run here (JobService owns the workers), so polls are answered at once.
#include <atomic>
#include <memory>
#include <string>

#include "server/auth.h"
#include "server/job_service.h"
#include "server/metrics.h"
#include "server/server_config.h"

namespace httplib {
class Server;
}

namespace penumbra::server {

class HttpServer {
 public:
  HttpServer(const ServerConfig& config, JobService& jobs, Metrics& metrics);
  ~HttpServer();
  // Binds host:port (port 0 = ephemeral); returns the bound port, or -1.
  int bind();
  // Serves until stop(); blocks.
  bool listen();
  void stop();
  // /readyz answers 503 from now on (shutdown has begun); the port stays open.
  void set_ready(bool ready) { ready_ = ready; }

  // The metrics label for a path: its route template, or "other" (bounded cardinality).
  static std::string route_template(const std::string& path);

 private:
  void install_routes();
  const ServerConfig config_;
  JobService& jobs_;
  Metrics& metrics_;
  BearerAuth auth_;
  std::unique_ptr<httplib::Server> server_;
  std::atomic<bool> ready_{true};
  std::atomic<int> sync_waiters_{0};
};

}  // namespace penumbra::server
