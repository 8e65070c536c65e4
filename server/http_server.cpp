#include "server/http_server.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <variant>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "api/embedded_documents.h"
#include "renderer/io/image_io.h"
#include "server/job_json.h"
#include "server/problem.h"
#include "server/request_guard.h"
#include "server/text_util.h"

namespace penumbra::server {
namespace {

using json = nlohmann::ordered_json;
constexpr const char* kIdPattern = "([0-9a-f]{24})";
constexpr int kDefaultPageSize = 20;
constexpr int kMaxPageSize = 100;

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(2, ' ', false, json::error_handler_t::replace) + "\n", "application/json");
}

void problem(httplib::Response& res, const httplib::Request& req, const Problem& p) {
  send_problem(res, p, req.path);
}

json diagnostics(const std::vector<api::Diagnostic>& ds) {
  json a = json::array();
  for (const auto& d : ds) a.push_back({{"pointer", d.pointer}, {"detail", d.message}});
  return a;
}

// Retry-After for an unfinished job: about when something will have changed.
double retry_after(const JobView& v) {
  if (v.progress && v.progress->fraction > 0) return std::clamp(v.progress->eta_seconds, 1.0, 10.0);
  return v.record.state == JobState::kQueued ? 2.0 : 1.0;
}

// format=png|exr wins; else the first acceptable type of Accept; else PNG.
std::variant<ImageFormat, Problem> negotiate_format(const httplib::Request& req) {
  if (req.has_param("format")) {
    const std::string f = ascii_lower(req.get_param_value("format"));
    if (f == "png") return ImageFormat::kPng;
    if (f == "exr") return ImageFormat::kExr;
    Problem p = make_problem(400, "invalid-parameter", "Invalid query parameter",
                             "format must be png or exr");
    p.extensions["errors"] = json::array({{{"parameter", "format"}, {"detail", "must be png or exr"}}});
    return p;
  }
  if (!req.has_header("Accept")) return ImageFormat::kPng;
  const std::string accept = ascii_lower(req.get_header_value("Accept"));
  std::size_t start = 0;
  while (start <= accept.size()) {
    const std::size_t comma = std::min(accept.find(',', start), accept.size());
    std::string range = accept.substr(start, comma - start);
    start = comma + 1;
    std::string params;
    if (const auto semi = range.find(';'); semi != std::string::npos) {
      params = range.substr(semi);
      range = range.substr(0, semi);
    }
    range = trim_ows(range);
    if (std::regex_search(params, std::regex(R"(q\s*=\s*0(\.0*)?\s*($|;))"))) continue;  // q=0: refused
    if (range == "image/png" || range == "image/*" || range == "*/*") return ImageFormat::kPng;
    if (range == "image/x-exr" || range == "image/exr" || range == "image/aces") return ImageFormat::kExr;
  }
  return make_problem(406, "not-acceptable", "Not Acceptable",
                      "results are image/png or image/x-exr (or use ?format=png|exr)");
}

const char* mime(ImageFormat f) { return f == ImageFormat::kPng ? "image/png" : "image/x-exr"; }
const char* extension(ImageFormat f) { return f == ImageFormat::kPng ? "png" : "exr"; }

std::variant<std::string, Problem> idempotency_key(const httplib::Request& req) {
  if (!req.has_header("Idempotency-Key")) return std::string();
  std::string key = trim_ows(req.get_header_value("Idempotency-Key"));
  // draft-ietf-httpapi-idempotency-key-header sends it as a quoted structured-field string.
  if (key.size() >= 2 && key.front() == '"' && key.back() == '"') key = key.substr(1, key.size() - 2);
  const bool printable = std::all_of(key.begin(), key.end(), [](char c) { return c > 0x20 && c < 0x7f; });
  if (key.empty() || key.size() > 255 || !printable)
    return make_problem(400, "invalid-idempotency-key", "Invalid Idempotency-Key",
                        "Idempotency-Key must be 1 to 255 visible ASCII characters");
  return key;
}

// The problem for a refused submission, or nullopt when the job exists.
std::optional<Problem> submit_problem(const SubmitOutcome& o) {
  using K = SubmitOutcome::Kind;
  switch (o.kind) {
    case K::kAccepted:
    case K::kReplayed:
      return std::nullopt;
    case K::kSyntax: {
      Problem p = make_problem(400, "malformed-json", "Malformed JSON",
                               o.errors.empty() ? "the body is not JSON" : o.errors.front().message);
      p.extensions["errors"] = diagnostics(o.errors);
      return p;
    }
    case K::kInvalid: {
      Problem p = make_problem(422, "invalid-scene", "Invalid scene",
                               std::to_string(o.errors.size()) + " error(s) in the scene; see errors");
      p.extensions["errors"] = diagnostics(o.errors);
      if (!o.warnings.empty()) p.extensions["warnings"] = diagnostics(o.warnings);
      return p;
    }
    case K::kKeyReused: {
      Problem p = make_problem(422, "idempotency-key-reused", "Idempotency-Key reused",
                               "this Idempotency-Key was used for a different scene (job " +
                                   o.record.id + ")");
      p.extensions["job"] = job_path(o.record.id);
      return p;
    }
    case K::kQueueFull: {
      Problem p = make_problem(429, "queue-full", "Queue full",
                               "the render queue is full (--max-queue); retry later");
      p.retry_after_seconds = o.retry_after_seconds;
      return p;
    }
    case K::kNotAccepting: {
      Problem p = make_problem(503, "shutting-down", "Shutting down",
                               "the server is shutting down and takes no new jobs");
      p.retry_after_seconds = o.retry_after_seconds;
      return p;
    }
  }
  return status_problem(500, "");
}

// Streams a result file; the open handle survives a concurrent DELETE of the job.
bool send_file(httplib::Response& res, const std::string& path, ImageFormat format, const std::string& id) {
  auto file = std::make_shared<std::ifstream>(path, std::ios::binary);
  if (!*file) return false;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return false;
  // Status left unset: the library answers 206 for a (single) Range request, else 200.
  res.set_header("Content-Disposition",
                 std::string("inline; filename=\"") + id + "." + extension(format) + "\"");
  res.set_header("ETag", "\"" + id + "-" + extension(format) + "\"");
  res.set_header("Cache-Control", "private, max-age=3600");
  res.set_content_provider(size, mime(format),
                           [file](size_t offset, size_t length, httplib::DataSink& sink) {
                             char buf[1 << 16];
                             file->seekg(std::streamoff(offset));
                             const auto n = std::min(length, sizeof buf);
                             file->read(buf, std::streamsize(n));
                             const auto got = file->gcount();
                             if (got <= 0) return false;
                             sink.write(buf, size_t(got));
                             return true;
                           });
  return true;
}

std::vector<std::string> allowed_methods(const std::string& route) {
  if (route == "/v1/jobs") return {"GET", "HEAD", "POST"};
  if (route == "/v1/jobs/{id}") return {"GET", "HEAD", "DELETE"};
  if (route == "/v1/render") return {"POST"};
  return {"GET", "HEAD"};
}

}  // namespace

std::string HttpServer::route_template(const std::string& path) {
  static const std::regex job(std::string("/v1/jobs/") + kIdPattern);
  static const std::regex result(std::string("/v1/jobs/") + kIdPattern + "/result");
  for (const char* fixed : {"/healthz", "/readyz", "/metrics", "/v1/openapi.json", "/v1/jobs", "/v1/render"})
    if (path == fixed) return fixed;
  if (std::regex_match(path, job)) return "/v1/jobs/{id}";
  if (std::regex_match(path, result)) return "/v1/jobs/{id}/result";
  return "other";
}

HttpServer::HttpServer(const ServerConfig& config, JobService& jobs, Metrics& metrics)
    : config_(config), jobs_(jobs), metrics_(metrics), auth_(config.token),
      server_(std::make_unique<httplib::Server>()) {
  httplib::Server& s = *server_;
  const int threads = config_.http_threads;
  s.new_task_queue = [threads] { return new httplib::ThreadPool(std::size_t(threads)); };
  s.set_payload_max_length(config_.max_body_bytes);
  s.set_read_timeout(std::chrono::duration<double>(config_.read_timeout_seconds));
  s.set_write_timeout(std::chrono::duration<double>(config_.write_timeout_seconds));
  s.set_keep_alive_timeout(config_.keep_alive_seconds);
  s.set_keep_alive_max_count(std::size_t(config_.keep_alive_max_requests));
  s.set_tcp_nodelay(true);  // small JSON answers to polls go out without Nagle's delay

  GuardSettings guard{config_.max_body_bytes};
  s.set_pre_routing_handler([this, guard](const httplib::Request& req, httplib::Response& res) {
    if (auto p = guard_request(req, guard, auth_)) {
      if (p->status == 401) res.set_header("WWW-Authenticate", "Bearer realm=\"penumbra\"");
      problem(res, req, *p);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  // Turns the library's own error answers (404, 400, 413 ...) into problem documents; 404 on a
  // known path with another method is 405.
  s.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request& req,
                                                             httplib::Response& res) {
    if (!res.body.empty() || res.content_length_ > 0) return httplib::Server::HandlerResponse::Unhandled;
    const std::string route = route_template(req.path);
    if (res.status == 404 && route != "other") {
      std::string allow;
      for (const auto& m : allowed_methods(route)) allow += (allow.empty() ? "" : ", ") + m;
      res.set_header("Allow", allow);
      problem(res, req, status_problem(405, req.method + " is not allowed here; allowed: " + allow));
    } else if (res.status == 404) {
      problem(res, req, status_problem(404, "no such resource"));
    } else {
      problem(res, req, status_problem(res.status, ""));
    }
    return httplib::Server::HandlerResponse::Handled;
  }));
  s.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    // The text goes to the log only: exception messages can hold paths and internals.
    std::string what = "unknown exception";
    try {
      if (ep) std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    std::fprintf(stderr, "penumbra serve: %s %s: internal error: %s\n", req.method.c_str(),
                 route_template(req.path).c_str(), what.c_str());
    res.headers.clear();
    problem(res, req, status_problem(500, "internal error; see the server log"));
  });
  const bool access_log = config_.access_log;
  s.set_logger([this, access_log](const httplib::Request& req, const httplib::Response& res) {
    metrics_.count_request(req.method, route_template(req.path), res.status);
    if (access_log)
      std::fprintf(stderr, "%s %s %d\n", req.method.c_str(), req.path.c_str(), res.status);
  });
  install_routes();
}

HttpServer::~HttpServer() = default;

int HttpServer::bind() {
  if (config_.port == 0) return server_->bind_to_any_port(config_.host);
  return server_->bind_to_port(config_.host, config_.port) ? config_.port : -1;
}

bool HttpServer::listen() { return server_->listen_after_bind(); }
void HttpServer::stop() { server_->stop(); }

void HttpServer::install_routes() {
  httplib::Server& s = *server_;
  const std::string id_route = std::string("/v1/jobs/") + kIdPattern;

  s.Get("/healthz", [](const httplib::Request&, httplib::Response& res) {
    send_json(res, 200, {{"status", "ok"}});
  });
  s.Get("/readyz", [this](const httplib::Request& req, httplib::Response& res) {
    if (ready_ && jobs_.accepting()) {
      send_json(res, 200, {{"status", "ready"}});
    } else {
      Problem p = make_problem(503, "shutting-down", "Shutting down", "not accepting new jobs");
      p.retry_after_seconds = 5;
      problem(res, req, p);
    }
  });
  s.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    Metrics::Gauges g = jobs_.gauges();
    g.ready = g.ready && ready_;
    res.set_content(metrics_.render_text(g), "text/plain; version=0.0.4; charset=utf-8");
  });
  s.Get("/v1/openapi.json", [](const httplib::Request& req, httplib::Response& res) {
    const std::string* doc = api::embedded_document("openapi.json");
    if (!doc) return problem(res, req, status_problem(404, "no OpenAPI document was built in"));
    res.set_content(*doc, "application/json");
  });

  s.Post("/v1/jobs", [this](const httplib::Request& req, httplib::Response& res) {
    auto key = idempotency_key(req);
    if (auto* p = std::get_if<Problem>(&key)) return problem(res, req, *p);
    const SubmitOutcome o = jobs_.submit(req.body, std::get<std::string>(key));
    if (auto p = submit_problem(o)) {
      metrics_.count_rejected(p->type.substr(p->type.rfind(':') + 1));
      return problem(res, req, *p);
    }
    auto view = jobs_.view(o.record.id);
    JobView v = view ? *view : JobView{o.record, std::nullopt, std::nullopt, false};
    if (o.kind == SubmitOutcome::Kind::kReplayed) res.set_header("Idempotent-Replayed", "true");
    res.set_header("Location", job_path(o.record.id));
    res.set_header("Retry-After", "1");
    send_json(res, 202, job_json(v));
  });

  s.Get("/v1/jobs", [this](const httplib::Request& req, httplib::Response& res) {
    int limit = kDefaultPageSize;
    std::optional<JobState> state;
    int64_t before = 0;
    auto bad = [&](const std::string& param, const std::string& detail) {
      Problem p = make_problem(400, "invalid-parameter", "Invalid query parameter", param + " " + detail);
      p.extensions["errors"] = json::array({{{"parameter", param}, {"detail", detail}}});
      problem(res, req, p);
    };
    if (req.has_param("limit")) {
      const std::string v = req.get_param_value("limit");
      if (v.empty() || v.size() > 4 || !std::all_of(v.begin(), v.end(), ::isdigit) ||
          std::stoi(v) < 1 || std::stoi(v) > kMaxPageSize)
        return bad("limit", "must be an integer from 1 to " + std::to_string(kMaxPageSize));
      limit = std::stoi(v);
    }
    if (req.has_param("state")) {
      state = job_state_from_string(req.get_param_value("state"));
      if (!state || *state == JobState::kDeleted)
        return bad("state", "must be one of queued, running, succeeded, failed, cancelled");
    }
    if (req.has_param("page_token")) {
      // Opaque to clients; here the hex sequence number of the last job of the previous page.
      const std::string t = req.get_param_value("page_token");
      if (t.empty() || t.size() > 15 || !std::all_of(t.begin(), t.end(), ::isxdigit))
        return bad("page_token", "is not a token this server issued");
      before = std::stoll(t, nullptr, 16);
    }
    std::vector<JobView> jobs = jobs_.list(state, before, limit + 1);
    json out = {{"jobs", json::array()}, {"next_page_token", nullptr}};
    if (int(jobs.size()) > limit) {
      jobs.resize(std::size_t(limit));
      char token[32];
      std::snprintf(token, sizeof token, "%llx", static_cast<unsigned long long>(jobs.back().record.seq));
      out["next_page_token"] = token;
    }
    for (const JobView& v : jobs) out["jobs"].push_back(job_json(v));
    send_json(res, 200, out);
  });

  s.Get(id_route, [this](const httplib::Request& req, httplib::Response& res) {
    const auto v = jobs_.view(req.matches[1]);
    if (!v) return problem(res, req, status_problem(404, "no job " + std::string(req.matches[1])));
    if (!is_finished(v->record.state))
      res.set_header("Retry-After", std::to_string(long(std::ceil(retry_after(*v)))));
    send_json(res, 200, job_json(*v));
  });

  s.Delete(id_route, [this](const httplib::Request& req, httplib::Response& res) {
    const std::string id = req.matches[1];
    switch (jobs_.cancel_or_delete(id, std::chrono::milliseconds(3000))) {
      case DeleteOutcome::kNotFound:
        return problem(res, req, status_problem(404, "no job " + id));
      case DeleteOutcome::kDeleted:
        res.status = 204;
        return;
      case DeleteOutcome::kCancelled:
      case DeleteOutcome::kCancelling: {
        const auto v = jobs_.view(id);
        if (!v) {
          res.status = 204;
          return;
        }
        // 200 once cancelled; 202 while the render is still winding down.
        send_json(res, is_finished(v->record.state) ? 200 : 202, job_json(*v));
        return;
      }
    }
  });

  s.Get(id_route + "/result", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string id = req.matches[1];
    auto format = negotiate_format(req);
    if (auto* p = std::get_if<Problem>(&format)) return problem(res, req, *p);
    const ImageFormat f = std::get<ImageFormat>(format);
    const auto v = jobs_.view(id);
    if (!v) return problem(res, req, status_problem(404, "no job " + id));
    const std::string preview_param = ascii_lower(req.get_param_value("preview"));
    const bool preview = preview_param == "true" || preview_param == "1";
    if (v->record.state == JobState::kSucceeded) {
      if (send_file(res, jobs_.result_path(id, extension(f)), f, id)) return;
      return problem(res, req, status_problem(404, "the result of job " + id + " is gone"));
    }
    if (preview && v->record.state == JobState::kRunning) {
      if (auto image = jobs_.preview(id)) {
        const auto bytes = encode_image(*image, f);
        res.set_header("Cache-Control", "no-store");
        res.set_header("Penumbra-Preview", "true");
        res.set_content(std::string(bytes.begin(), bytes.end()), mime(f));
        return;
      }
    }
    Problem p = make_problem(409, "result-not-ready", "Result not ready",
                             std::string("job ") + id + " is " + to_string(v->record.state) +
                                 (is_finished(v->record.state) ? " and has no result"
                                                                : "; poll the job and retry"));
    p.extensions["state"] = to_string(v->record.state);
    p.extensions["job"] = job_path(id);
    if (!is_finished(v->record.state)) p.retry_after_seconds = retry_after(*v);
    problem(res, req, p);
  });

  s.Post("/v1/render", [this](const httplib::Request& req, httplib::Response& res) {
    auto format = negotiate_format(req);
    if (auto* p = std::get_if<Problem>(&format)) return problem(res, req, *p);
    auto key = idempotency_key(req);
    if (auto* p = std::get_if<Problem>(&key)) return problem(res, req, *p);
    // A waiting synchronous request holds an HTTP thread: keep some free for polls.
    const int max_waiters = std::max(1, config_.http_threads / 2);
    if (sync_waiters_.fetch_add(1) >= max_waiters) {
      sync_waiters_.fetch_sub(1);
      Problem p = make_problem(503, "too-many-synchronous-renders", "Too many synchronous renders",
                               "use POST /v1/jobs and poll, or retry later");
      p.retry_after_seconds = jobs_.retry_after_for_queue();
      return problem(res, req, p);
    }
    struct Release {
      std::atomic<int>& n;
      ~Release() { n.fetch_sub(1); }
    } release{sync_waiters_};
    const SubmitOutcome o = jobs_.submit(req.body, std::get<std::string>(key));
    if (auto p = submit_problem(o)) return problem(res, req, *p);
    const std::string id = o.record.id;
    res.set_header("Content-Location", job_path(id));
    const auto done = jobs_.wait_finished(id, std::chrono::steady_clock::now() + std::chrono::hours(24));
    if (!done) return problem(res, req, status_problem(404, "job " + id + " was deleted"));
    const ImageFormat f = std::get<ImageFormat>(format);
    if (done->state == JobState::kSucceeded && send_file(res, jobs_.result_path(id, extension(f)), f, id)) return;
    Problem p;
    if (done->state == JobState::kFailed) {
      p = make_problem(500, "render-failed", "Render failed", "the render of job " + id + " failed");
      if (!done->error_json.empty()) p.extensions["error"] = json::parse(done->error_json);
    } else if (done->state == JobState::kCancelled) {
      p = make_problem(409, "cancelled", "Cancelled", "job " + id + " was cancelled");
    } else {
      p = make_problem(503, "shutting-down", "Shutting down",
                       "the server is shutting down; job " + id + " stays queued, poll it");
      p.retry_after_seconds = 5;
      res.set_header("Location", job_path(id));
    }
    p.extensions["job"] = job_path(id);
    problem(res, req, p);
  });
}

}  // namespace penumbra::server
