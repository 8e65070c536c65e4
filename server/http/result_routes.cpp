// GET /v1/jobs/{id}/result: the image of a finished job, or the progressive preview of a
// running one (?preview=true), in the negotiated format; ?layer=albedo|normal|depth one output
// layer alone, ?layout=blender the EXR in Blender's multi-layer layout (docs/output-layers.md).
#include <httplib.h>

#include <algorithm>
#include <iterator>
#include <variant>

#include "renderer/scene/scene_input.h"
#include "server/http/accept_negotiation.h"
#include "server/http/job_json.h"
#include "server/http/request_values.h"
#include "server/http/result_response.h"
#include "server/http/route_context.h"
#include "server/http/route_table.h"
#include "server/text_util.h"

namespace penumbra::server {
namespace {

// 422 naming the query parameter, as invalid_parameter's 400 does for a malformed one: the value
// is well-formed but names nothing this route serves.
Problem unprocessable_parameter(const std::string& slug, const std::string& title,
                                const std::string& parameter, const std::string& what) {
  Problem p = make_problem(422, slug, title, parameter + " " + what);
  p.extensions["errors"] = nlohmann::ordered_json::array({{{"parameter", parameter}, {"detail", what}}});
  return p;
}

// Which result file the query asks for: "" (the beauty image), "blender", or a layer's name.
std::variant<std::string, Problem> result_variant(const httplib::Request& req) {
  const auto layer = param_value(req, "layer");
  const auto layout = param_value(req, "layout");
  std::string variant;
  if (layer && *layer != "beauty") {
    const auto* end = std::end(kOutputLayerNames);
    if (std::find(std::begin(kOutputLayerNames), end, *layer) == end && *layer != kNoisyLayerName)
      return unprocessable_parameter("unknown-layer", "Unknown layer", "layer",
                                     "must be one of beauty, albedo, normal, depth, noisy");
    variant = *layer;
  }
  if (layout && *layout != "plain") {
    if (*layout != "blender")
      return unprocessable_parameter("unknown-layout", "Unknown layout", "layout",
                                     "must be plain or blender");
    if (!variant.empty())
      return unprocessable_parameter("layout-conflict", "Layout and layer conflict", "layout",
                                     "blender is the whole result in one EXR; it takes no layer");
    variant = "blender";
  }
  return variant;
}

void get_result(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  const auto variant = result_variant(req);
  if (const auto* p = std::get_if<Problem>(&variant)) return send_problem(res, req, *p);
  const std::string& which = std::get<std::string>(variant);
  // Blender's layout exists as EXR only: it is the default format there, and PNG is refused.
  auto format_param = param_value(req, "format");
  if (which == "blender" && !format_param) format_param = "exr";
  const auto format = negotiate_image_format(format_param, header_value(req, "Accept"));
  if (const auto* p = std::get_if<Problem>(&format)) return send_problem(res, req, *p);
  const ImageFormat f = std::get<ImageFormat>(format);
  if (which == "blender" && f != ImageFormat::kExr)
    return send_problem(res, req,
                        unprocessable_parameter("layout-conflict", "Layout and layer conflict",
                                                "layout", "blender is an EXR layout; ask format=exr"));
  const auto v = c.jobs.view(id);
  if (!v) return send_problem(res, req, status_problem(404, "no job " + id));
  const JobState state = v->record.state;
  if (state == JobState::kSucceeded) {
    if (send_result(res, c.jobs, id, f, header_value(req, "Range"), which)) return;
    if (which.empty() || !c.jobs.open_result(id, "png", std::nullopt))
      return send_problem(res, req, status_problem(404, "the result of job " + id + " is gone"));
    // The Blender EXR is stored for jobs with output layers only (result_files.h).
    Problem p = make_problem(404, "layer-not-rendered", "Layer not rendered",
                             which == "blender"
                                 ? "job " + id + " has no output layers, so no Blender layout; its "
                                   "image is the plain EXR (format=exr)"
                                 : "job " + id + " did not ask for the " + which +
                                       " layer; list it in the scene's render.outputs");
    p.extensions["layer"] = which;
    return send_problem(res, req, p);
  }
  const std::string preview = ascii_lower(req.get_param_value("preview"));
  if ((preview == "true" || preview == "1") && state == JobState::kRunning && which.empty()) {
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
