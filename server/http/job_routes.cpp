// POST /v1/jobs (submit), GET /v1/jobs (list), GET and DELETE /v1/jobs/{id}.
#include <httplib.h>

#include <cmath>
#include <cstdio>

#include "server/http/idempotency_key.h"
#include "server/http/job_json.h"
#include "server/http/json_response.h"
#include "server/http/one_shot_job.h"
#include "server/http/paging.h"
#include "server/http/request_values.h"
#include "server/http/route_context.h"
#include "server/http/route_table.h"
#include "server/http/submission_problem.h"
#include "server/storage/store_error.h"

namespace penumbra::server {
namespace {

using json = nlohmann::ordered_json;

void submit(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto key = parse_idempotency_key(header_value(req, "Idempotency-Key"));
  if (const auto* p = std::get_if<Problem>(&key)) return send_problem(res, req, *p);
  // curl -F ... and --data-binary @model.glb forms become the JSON envelope (one_shot_job.h).
  std::string one_shot_body;
  if (is_one_shot_job(req)) {
    auto body = one_shot_job_body(c, req);
    if (const auto* p = std::get_if<Problem>(&body)) return send_problem(res, req, *p);
    one_shot_body = std::move(std::get<std::string>(body));
  }
  const SubmitOutcome o = c.jobs.submit(is_one_shot_job(req) ? one_shot_body : req.body,
                                        std::get<std::string>(key));
  if (auto p = submission_problem(o)) {
    c.metrics.count_rejected(p->type.substr(p->type.rfind(':') + 1));
    return send_problem(res, req, *p);
  }
  const auto view = c.jobs.view(o.record.id);
  const JobView v = view ? *view : JobView{o.record, std::nullopt, std::nullopt, false, std::nullopt};
  if (o.kind == SubmitOutcome::Kind::kReplayed) res.set_header("Idempotent-Replayed", "true");
  res.set_header("Location", job_path(o.record.id));
  res.set_header("Retry-After", "1");
  send_json(res, 202, job_json(v));
}

void list(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto query = parse_list_query(
      {param_value(req, "limit"), param_value(req, "state"), param_value(req, "page_token")});
  if (const auto* p = std::get_if<Problem>(&query)) return send_problem(res, req, *p);
  const ListQuery& q = std::get<ListQuery>(query);
  // Queued jobs are listed in the order they will run; the others newest first.
  const bool run_order = q.state == JobState::kQueued;
  std::vector<JobView> jobs =
      run_order ? c.jobs.list_queued(
                      q.before_seq > 0
                          ? std::optional<JobBackend::RunKey>(
                                {run_order_from_token(q.before_seq).first,
                                 run_order_from_token(q.before_seq).second})
                          : std::nullopt,
                      q.limit + 1)
                : c.jobs.list(q.state, q.before_seq, q.limit + 1);
  json out = {{"jobs", json::array()}, {"next_page_token", nullptr}};
  if (int(jobs.size()) > q.limit) {
    jobs.resize(std::size_t(q.limit));
    const JobRecord& last = jobs.back().record;
    out["next_page_token"] =
        run_order ? run_order_page_token(last.priority, last.seq) : page_token(last.seq);
  }
  for (const JobView& v : jobs) out["jobs"].push_back(job_json(v));
  send_json(res, 200, out);
}

void get(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  const auto v = c.jobs.view(id);
  if (!v) return send_problem(res, req, status_problem(404, "no job " + id));
  if (!is_finished(v->record.state))
    res.set_header("Retry-After", std::to_string(long(std::ceil(retry_after_seconds(*v)))));
  send_json(res, 200, job_json(*v));
}

void cancel_or_delete(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  DeleteOutcome outcome;
  try {
    outcome = c.jobs.cancel_or_delete(id, std::chrono::milliseconds(3000));
  } catch (const StoreError& e) {
    // A full disk can fail the commit of the tombstone. The job is gone from memory and its
    // files are removed (space freed), so a repeated DELETE answers 204; this one says the
    // record could not be made durable yet, never 500.
    std::fprintf(stderr, "penumbra serve: DELETE %s: %s\n", id.c_str(), e.what());
    Problem p = make_problem(503, "storage-error", "Storage error",
                             "the deletion of job " + id +
                                 " could not be recorded on disk (is it full?); retry");
    p.retry_after_seconds = 5;
    return send_problem(res, req, p);
  }
  switch (outcome) {
    case DeleteOutcome::kNotFound:
      return send_problem(res, req, status_problem(404, "no job " + id));
    case DeleteOutcome::kDeleted:
      res.status = 204;
      return;
    case DeleteOutcome::kCancelled:
    case DeleteOutcome::kCancelling: {
      const auto v = c.jobs.view(id);
      if (!v) {
        res.status = 204;
        return;
      }
      // 200 once cancelled; 202 while the render is still winding down.
      send_json(res, is_finished(v->record.state) ? 200 : 202, job_json(*v));
      return;
    }
  }
}

}  // namespace

void add_job_routes(httplib::Server& s, const RouteContext& c) {
  s.Post("/v1/jobs",
         [&c](const httplib::Request& req, httplib::Response& res) { submit(c, req, res); });
  s.Get("/v1/jobs",
        [&c](const httplib::Request& req, httplib::Response& res) { list(c, req, res); });
  s.Get(kJobRoute, [&c](const httplib::Request& req, httplib::Response& res) { get(c, req, res); });
  s.Delete(kJobRoute, [&c](const httplib::Request& req, httplib::Response& res) {
    cancel_or_delete(c, req, res);
  });
}

}  // namespace penumbra::server
