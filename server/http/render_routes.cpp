// POST /v1/render: submits an ordinary job, waits for it on the HTTP thread and answers its
// image. Waiting requests are bounded so HTTP threads stay free for polls.
#include <httplib.h>

#include <memory>

#include "server/http/accept_negotiation.h"
#include "server/http/idempotency_key.h"
#include "server/http/job_json.h"
#include "server/http/request_values.h"
#include "server/http/result_response.h"
#include "server/http/route_context.h"
#include "server/http/submission_problem.h"

namespace penumbra::server {
namespace {

// A synchronous render waits this long at most (the render's own limit is far shorter).
constexpr auto kMaxWait = std::chrono::hours(24);

void render(const RouteContext& c, std::atomic<int>& waiters, const httplib::Request& req,
            httplib::Response& res) {
  const auto format =
      negotiate_image_format(param_value(req, "format"), header_value(req, "Accept"));
  if (const auto* p = std::get_if<Problem>(&format)) return send_problem(res, req, *p);
  const auto key = parse_idempotency_key(header_value(req, "Idempotency-Key"));
  if (const auto* p = std::get_if<Problem>(&key)) return send_problem(res, req, *p);
  // A waiting synchronous request holds an HTTP thread: keep some free for polls.
  const int max_waiters = std::max(1, c.config.http_threads / 2);
  if (waiters.fetch_add(1) >= max_waiters) {
    waiters.fetch_sub(1);
    Problem p = make_problem(503, "too-many-synchronous-renders", "Too many synchronous renders",
                             "use POST /v1/jobs and poll, or retry later");
    p.retry_after_seconds = c.jobs.retry_after_for_queue();
    return send_problem(res, req, p);
  }
  struct Release {
    std::atomic<int>& n;
    ~Release() { n.fetch_sub(1); }
  } release{waiters};
  const SubmitOutcome o = c.jobs.submit(req.body, std::get<std::string>(key));
  if (auto p = submission_problem(o)) return send_problem(res, req, *p);
  const std::string id = o.record.id;
  res.set_header("Content-Location", job_path(id));
  const auto done = c.jobs.wait_finished(id, std::chrono::steady_clock::now() + kMaxWait);
  if (!done) return send_problem(res, req, status_problem(404, "job " + id + " was deleted"));
  const ImageFormat f = std::get<ImageFormat>(format);
  if (done->state == JobState::kSucceeded && send_result(res, c.jobs, id, f, header_value(req, "Range"))) return;
  Problem p;
  if (done->state == JobState::kFailed) {
    p = make_problem(500, "render-failed", "Render failed", "the render of job " + id + " failed");
    if (!done->error_json.empty())
      p.extensions["error"] = nlohmann::ordered_json::parse(done->error_json);
  } else if (done->state == JobState::kCancelled) {
    p = make_problem(409, "cancelled", "Cancelled", "job " + id + " was cancelled");
  } else {
    p = make_problem(503, "shutting-down", "Shutting down",
                     "the server is shutting down; job " + id + " stays queued, poll it");
    p.retry_after_seconds = 5;
    res.set_header("Location", job_path(id));
  }
  p.extensions["job"] = job_path(id);
  send_problem(res, req, p);
}

}  // namespace

void add_render_routes(httplib::Server& s, const RouteContext& c) {
  auto waiters = std::make_shared<std::atomic<int>>(0);
  s.Post("/v1/render", [&c, waiters](const httplib::Request& req, httplib::Response& res) {
    render(c, *waiters, req, res);
  });
}

}  // namespace penumbra::server
