// GET /v1/jobs/{id}/result: the image of a finished job, or the progressive preview of a
// running one (?preview=true), in the negotiated format.
#include <httplib.h>

#include "server/http/accept_negotiation.h"
#include "server/http/job_json.h"
#include "server/http/request_values.h"
#include "server/http/result_response.h"
#include "server/http/route_context.h"
#include "server/http/route_table.h"
#include "server/http/text_util.h"

namespace penumbra::server {
namespace {

void get_result(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  const auto format =
      negotiate_image_format(param_value(req, "format"), header_value(req, "Accept"));
  if (const auto* p = std::get_if<Problem>(&format)) return send_problem(res, req, *p);
  const ImageFormat f = std::get<ImageFormat>(format);
  const auto v = c.jobs.view(id);
  if (!v) return send_problem(res, req, status_problem(404, "no job " + id));
  const JobState state = v->record.state;
  if (state == JobState::kSucceeded) {
    if (send_result(res, c.jobs, id, f, header_value(req, "Range"))) return;
    return send_problem(res, req, status_problem(404, "the result of job " + id + " is gone"));
  }
  const std::string preview = ascii_lower(req.get_param_value("preview"));
  if ((preview == "true" || preview == "1") && state == JobState::kRunning) {
    if (const auto image = c.jobs.preview(id)) {
      const auto bytes = encode_image(*image, f);
      res.set_header("Cache-Control", "no-store");
      res.set_header("Penumbra-Preview", "true");
      res.set_content(std::string(bytes.begin(), bytes.end()), mime_type(f));
      return;
    }
  }
  Problem p =
      make_problem(409, "result-not-ready", "Result not ready",
                   std::string("job ") + id + " is " + to_string(state) +
                       (is_finished(state) ? " and has no result" : "; poll the job and retry"));
  p.extensions["state"] = to_string(state);
  p.extensions["job"] = job_path(id);
  if (!is_finished(state)) p.retry_after_seconds = retry_after_seconds(*v);
  send_problem(res, req, p);
}

}  // namespace

void add_result_routes(httplib::Server& s, const RouteContext& c) {
  s.Get(kResultRoute,
        [&c](const httplib::Request& req, httplib::Response& res) { get_result(c, req, res); });
}

}  // namespace penumbra::server
