#include "server/http/http_server.h"

#include <httplib.h>

#include <algorithm>
#include <cstdio>

#include "api/job_submission.h"
#include "server/http/connection_pool.h"
#include "server/http/job_json.h"
#include "server/http/json_response.h"
#include "server/http/problem.h"
#include "server/http/request_guard.h"
#include "server/http/route_table.h"
#include "server/loopback.h"

namespace penumbra::server {
namespace {

// A burst of connects beyond the listen queue waits for SYN retries (1 s, 3 s ...).
constexpr int kListenBacklog = 1024;

ConnectionLimits connection_limits(const ServerConfig& c) {
  ConnectionLimits l;
  l.max_header_count = std::size_t(c.max_headers);
  l.max_header_bytes = c.max_header_bytes;
  l.header_seconds = c.header_timeout_seconds;
  l.body_grace_seconds = c.read_timeout_seconds;
  l.write_grace_seconds = c.write_timeout_seconds;
  l.min_bytes_per_second = double(c.min_transfer_rate);
  return l;
}

// The library answers these itself, before any handler; say what they mean.
std::string library_error_detail(int status) {
  switch (status) {
    case 400:
      return "the request line or a header could not be parsed";
    case 413:
      return "the body is larger than the server accepts (--max-body)";
    case 414:
      return "the request target is too long";
    case 416:
      return "the Range header is not a byte range 'bytes=first-last', 'bytes=first-' or "
             "'bytes=-suffix'";
    default:
      return "";
  }
}

}  // namespace

HttpServer::HttpServer(const ServerConfig& config, JobBackend& jobs, Metrics& metrics)
    : config_(config),
      metrics_(metrics),
      auth_(config.token),
      context_{config_, jobs, metrics, ready_},
      server_(std::make_unique<GuardedServer>(connection_limits(config), kListenBacklog, metrics)) {
  httplib::Server& s = *server_;
  // cpp-httplib's defaults are unsafe for a public service: every limit is set here, and the
  // per-connection ones (deadlines, head caps) in GuardedServer / ConnectionStream.
  const int threads = config_.http_threads;
  s.new_task_queue = [threads] {
    return new ConnectionPool(std::size_t(threads), std::chrono::seconds(10));
  };
  // The largest body any route takes; each route's own limit is checked by the guard from
  // Content-Length before a byte is read (request_guard.cpp).
  s.set_payload_max_length(std::max<std::size_t>(config_.max_body_bytes,
                                                 std::size_t(config_.max_asset_bytes)));
  s.set_keep_alive_timeout(config_.keep_alive_seconds);
  s.set_keep_alive_max_count(std::size_t(config_.keep_alive_max_requests));
  s.set_tcp_nodelay(true);  // small JSON answers to polls go out without Nagle's delay
  install_handlers();
  add_service_routes(s, context_);
  add_job_routes(s, context_);
  add_result_routes(s, context_);
  add_render_routes(s, context_);
  add_asset_routes(s, context_);
  add_dashboard_routes(s, context_);
  add_event_routes(s, context_);
  jobs.set_webhook_body(webhook_body);
}

HttpServer::~HttpServer() = default;

bool HttpServer::answer_known_asset(const httplib::Request& req, httplib::Response& res) {
  constexpr std::string_view kPrefix = "/v1/assets/";
  AssetStore* store = context_.jobs.assets();
  if (!store || req.path.compare(0, kPrefix.size(), kPrefix) != 0) return false;
  const std::string hash = req.path.substr(kPrefix.size());
  if (!api::is_sha256_hex(hash)) return false;
  const auto size = store->size_of(hash);
  if (!size) return false;
  res.set_header("Location", req.path);
  send_json(res, 200, {{"hash", "sha256:" + hash}, {"size", *size}});
  return true;
}

void HttpServer::install_handlers() {
  httplib::Server& s = *server_;
  const GuardSettings guard{config_.max_body_bytes, std::size_t(config_.max_asset_bytes)};
  // The library asks this before routing, so before the pre-routing guard, whenever a client
  // sends "Expect: 100-continue"; its default answers 100 to everything. Here the guard runs
  // first (a body over its limit or without credentials is refused before it is sent), and an
  // upload of an asset the store already holds is answered at once: its body is never sent
  // (issue 12). Any status but 100 and 417 is written as the final answer.
  s.set_expect_100_continue_handler(
      [this, guard](const httplib::Request& req, httplib::Response& res) -> int {
        // The library writes such an answer without a Content-Length of its own; the body is
        // never read, so the connection closes after it (ConnectionStream sees the unread body).
        const auto early_answer = [&req, &res] {
          res.set_header("Content-Length", std::to_string(res.body.size()));
          auto& headers = const_cast<httplib::Request&>(req).headers;
          headers.erase("Connection");
          headers.emplace("Connection", "close");
          return res.status;
        };
        if (auto p = guard_request(req, guard, auth_)) {
          if (p->status == 401) res.set_header("WWW-Authenticate", "Bearer realm=\"penumbra\"");
          send_problem(res, req, *p);
          return early_answer();
        }
        if (req.method == "PUT" && answer_known_asset(req, res)) return early_answer();
        return 100;
      });
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
        // Methods the library parses but cannot route (TRACE, CONNECT) come back as 400: on a
        // known path they are 405 like any other method it does not answer.
        const bool unroutable_method =
            res.status == 400 && (req.method == "TRACE" || req.method == "CONNECT");
        if (unroutable_method) res.status = 404;  // then 405 with Allow on a known path
        if (res.status == 404 && route != "other") {
          std::string allow;
          for (const auto& m : allowed_methods(route)) allow += (allow.empty() ? "" : ", ") + m;
          res.set_header("Allow", allow);
          send_problem(res, req,
                       status_problem(405, req.method + " is not allowed here; allowed: " + allow));
        } else if (res.status == 404) {
          send_problem(res, req, status_problem(404, "no such resource"));
        } else {
          send_problem(res, req, status_problem(res.status, library_error_detail(res.status)));
        }
        return httplib::Server::HandlerResponse::Handled;
      }));
  s.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        // The text goes to the log only: exception messages can hold paths and internals.
        std::string what = "unknown exception";
        try {
          if (ep) std::rethrow_exception(ep);
        } catch (const StoreError& e) {
          // The job store did not answer (farm: PostgreSQL down or restarting): worth a retry.
          std::fprintf(stderr, "penumbra serve: %s %s: store unavailable: %s\n",
                       req.method.c_str(), route_template(req.path).c_str(), e.what());
          res.headers.clear();
          Problem p = make_problem(503, "store-unavailable", "Job store unavailable",
                                   "the job store does not answer; retry shortly");
          p.retry_after_seconds = 2;
          send_problem(res, req, p);
          return;
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
  const int port = config_.port == 0 ? server_->bind_to_any_port(config_.host)
                                     : (server_->bind_to_port(config_.host, config_.port) ? config_.port : -1);
  if (port > 0) server_->widen_backlog();
  return port;
}

bool HttpServer::bound_to_loopback() const {
  return is_loopback_socket(int(server_->listening_socket()));
}

bool HttpServer::listen() { return server_->listen_after_bind(); }
void HttpServer::stop() { server_->stop(); }

}  // namespace penumbra::server
