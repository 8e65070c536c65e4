#include "server/http/http_server.h"

#include <httplib.h>

#include <cstdio>

#include "server/http/problem.h"
#include "server/http/request_guard.h"
#include "server/http/route_table.h"

namespace penumbra::server {

HttpServer::HttpServer(const ServerConfig& config, JobService& jobs, Metrics& metrics)
    : config_(config),
      metrics_(metrics),
      auth_(config.token),
      context_{config_, jobs, metrics, ready_},
      server_(std::make_unique<httplib::Server>()) {
  httplib::Server& s = *server_;
  // cpp-httplib's defaults are unsafe for a public service: every limit is set here.
  const int threads = config_.http_threads;
  s.new_task_queue = [threads] { return new httplib::ThreadPool(std::size_t(threads)); };
  s.set_payload_max_length(config_.max_body_bytes);
  s.set_read_timeout(std::chrono::duration<double>(config_.read_timeout_seconds));
  s.set_write_timeout(std::chrono::duration<double>(config_.write_timeout_seconds));
  s.set_keep_alive_timeout(config_.keep_alive_seconds);
  s.set_keep_alive_max_count(std::size_t(config_.keep_alive_max_requests));
  s.set_tcp_nodelay(true);  // small JSON answers to polls go out without Nagle's delay
  install_handlers();
  add_service_routes(s, context_);
  add_job_routes(s, context_);
  add_result_routes(s, context_);
  add_render_routes(s, context_);
}

HttpServer::~HttpServer() = default;

void HttpServer::install_handlers() {
  httplib::Server& s = *server_;
  const GuardSettings guard{config_.max_body_bytes};
  s.set_pre_routing_handler([this, guard](const httplib::Request& req, httplib::Response& res) {
    if (auto p = guard_request(req, guard, auth_)) {
      if (p->status == 401) res.set_header("WWW-Authenticate", "Bearer realm=\"penumbra\"");
      send_problem(res, req, *p);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  // Turns the library's own error answers (404, 400, 413 ...) into problem documents; 404 on a
  // known path with another method is 405.
  s.set_error_handler(
      httplib::Server::HandlerWithResponse([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty() || res.content_length_ > 0)
          return httplib::Server::HandlerResponse::Unhandled;
        const std::string route = route_template(req.path);
        if (res.status == 404 && route != "other") {
          std::string allow;
          for (const auto& m : allowed_methods(route)) allow += (allow.empty() ? "" : ", ") + m;
          res.set_header("Allow", allow);
          send_problem(res, req,
                       status_problem(405, req.method + " is not allowed here; allowed: " + allow));
        } else if (res.status == 404) {
          send_problem(res, req, status_problem(404, "no such resource"));
        } else {
          send_problem(res, req, status_problem(res.status, ""));
        }
        return httplib::Server::HandlerResponse::Handled;
      }));
  s.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        // The text goes to the log only: exception messages can hold paths and internals.
        std::string what = "unknown exception";
        try {
          if (ep) std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
          // not a std::exception: nothing more to say than "unknown exception", logged below
        }
        std::fprintf(stderr, "penumbra serve: %s %s: internal error: %s\n", req.method.c_str(),
                     route_template(req.path).c_str(), what.c_str());
        res.headers.clear();
        send_problem(res, req, status_problem(500, "internal error; see the server log"));
      });
  const bool access_log = config_.access_log;
  s.set_logger([this, access_log](const httplib::Request& req, const httplib::Response& res) {
    metrics_.count_request(req.method, route_template(req.path), res.status);
    if (access_log)
      std::fprintf(stderr, "%s %s %d\n", req.method.c_str(), req.path.c_str(), res.status);
  });
}

int HttpServer::bind() {
  if (config_.port == 0) return server_->bind_to_any_port(config_.host);
  return server_->bind_to_port(config_.host, config_.port) ? config_.port : -1;
}

bool HttpServer::listen() { return server_->listen_after_bind(); }
void HttpServer::stop() { server_->stop(); }

}  // namespace penumbra::server
