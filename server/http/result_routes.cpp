// GET /v1/jobs/{id}/result: the image of a finished job, or the progressive preview of a
// running one (?preview=true), in the negotiated format; ?layer=albedo|normal|depth one output
// layer alone, ?layout=blender the EXR in Blender's multi-layer layout (docs/output-layers.md);
// ?frame=N one frame of an animation. GET /v1/jobs/{id}/frames.tar: all of an animation's frames
// (docs/animation-and-windows.md, "In the render service").
#include <httplib.h>

#include <algorithm>
#include <iterator>
#include <variant>

#include "renderer/scene/scene_input.h"
#include "server/http/accept_negotiation.h"
#include "server/http/byte_range.h"
#include "server/http/frame_archive.h"
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

// Blender's layout exists as EXR only: any other format for it is a 422 naming `layout`.
std::optional<Problem> blender_layout_conflict(const std::string& which, ImageFormat f) {
  if (which != "blender" || f == ImageFormat::kExr) return std::nullopt;
  return unprocessable_parameter("layout-conflict", "Layout and layer conflict", "layout",
                                 "blender is an EXR layout; ask format=exr");
}

// ?frame=N: which frame of an animation. A malformed number is a 400 naming the parameter.
std::variant<std::optional<int>, Problem> frame_param(const httplib::Request& req) {
  const auto text = param_value(req, "frame");
  if (!text) return std::optional<int>();
  const std::string& t = *text;
  const std::size_t digits_from = !t.empty() && t[0] == '-' ? 1 : 0;
  if (t.size() <= digits_from || t.size() > digits_from + 7 ||
      t.find_first_not_of("0123456789", digits_from) != std::string::npos)
    return invalid_parameter("frame", "must be a frame number (an integer such as 17)");
  return std::optional<int>(std::stoi(t));
}

// A frame the job does not have (yet): 404 naming the parameter, with the frames it has.
Problem frame_problem(const JobView& v, int frame, const std::string& what) {
  const JobRecord& r = v.record;
  Problem p = make_problem(404, "frame-not-available", "Frame not available",
                           "frame " + std::to_string(frame) + " " + what);
  p.extensions["errors"] =
      nlohmann::ordered_json::array({{{"parameter", "frame"}, {"detail", p.detail}}});
  p.extensions["frames"] = {{"first", r.frame_first}, {"last", r.frame_last}, {"done", r.frames_done}};
  p.extensions["state"] = to_string(r.state);
  if (!is_finished(r.state)) p.retry_after_seconds = retry_after_seconds(v);
  return p;
}

// The progressive image of the running job (of the frame being rendered, for an animation).
bool send_preview(const RouteContext& c, const JobView& v, ImageFormat f, httplib::Response& res) {
  const auto image = c.jobs.preview(v.record.id);
  if (!image) return false;
  const auto bytes = encode_image(*image, f);
  res.set_header("Cache-Control", "no-store");
  res.set_header("Penumbra-Preview", "true");
  if (v.record.frame_count() > 0)
    res.set_header("Penumbra-Frame", std::to_string(v.record.frame_first + v.record.frames_done));
  res.set_content(std::string(bytes.begin(), bytes.end()), mime_type(f));
  return true;
}

void get_result(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  const auto frame_or = frame_param(req);
  if (const auto* p = std::get_if<Problem>(&frame_or)) return send_problem(res, req, *p);
  const std::optional<int> frame = std::get<std::optional<int>>(frame_or);
  const auto variant = result_variant(req);
  if (const auto* p = std::get_if<Problem>(&variant)) return send_problem(res, req, *p);
  const std::string& which = std::get<std::string>(variant);
  // Blender's layout exists as EXR only: it is the default format there, and PNG is refused.
  auto format_param = param_value(req, "format");
  if (which == "blender" && !format_param) format_param = "exr";
  const auto format = negotiate_image_format(format_param, header_value(req, "Accept"));
  if (const auto* p = std::get_if<Problem>(&format)) return send_problem(res, req, *p);
  const ImageFormat f = std::get<ImageFormat>(format);
  if (auto p = blender_layout_conflict(which, f)) return send_problem(res, req, *p);
  const auto v = c.jobs.view(id);
  if (!v) return send_problem(res, req, status_problem(404, "no job " + id));
  const JobState state = v->record.state;
  const std::string preview = ascii_lower(req.get_param_value("preview"));
  const bool wants_preview = preview == "true" || preview == "1";
  if (frame) {
    const JobRecord& r = v->record;
    if (r.frame_count() == 0)
      return send_problem(res, req,
                          unprocessable_parameter("not-an-animation", "Not an animation", "frame",
                                                  "names a frame, but job " + id +
                                                      " renders a still (its scene has no "
                                                      "\"animation\")"));
    if (*frame < r.frame_first || *frame > r.frame_last)
      return send_problem(res, req,
                          frame_problem(*v, *frame,
                                        "is outside the animation's frames [" +
                                            std::to_string(r.frame_first) + ", " +
                                            std::to_string(r.frame_last) + "]"));
    // Done is asked of the backend, not read off frames_done: a farm finishes frames in any
    // order (one task each), one node in order. Every done frame has its PNG (result_files.h).
    if (c.jobs.open_result(id, "png", frame)) {
      if (send_result(res, c.jobs, id, f, header_value(req, "Range"), which, frame)) return;
    } else if (wants_preview && state == JobState::kRunning && which.empty() &&
               *frame == r.frame_first + r.frames_done && send_preview(c, *v, f, res)) {
      return;
    } else {
      return send_problem(res, req,
                          frame_problem(*v, *frame,
                                        is_finished(state) ? "was not rendered (the job is " +
                                                                 std::string(to_string(state)) + ")"
                                                           : "is not rendered yet; retry later"));
    }
    // A finished frame without the file asked for: a layer the scene did not ask for, or gone.
  } else if (state == JobState::kSucceeded) {
    if (send_result(res, c.jobs, id, f, header_value(req, "Range"), which)) return;
  }
  if (state == JobState::kSucceeded || frame) {
    if (which.empty() || !c.jobs.open_result(id, "png", frame))
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
  if (wants_preview && state == JobState::kRunning && which.empty() && send_preview(c, *v, f, res))
    return;
  Problem p =
      make_problem(409, "result-not-ready", "Result not ready",
                   std::string("job ") + id + " is " + to_string(state) +
                       (is_finished(state) ? " and has no result" : "; poll the job and retry"));
  p.extensions["state"] = to_string(state);
  p.extensions["job"] = job_path(id);
  if (!is_finished(state)) p.retry_after_seconds = retry_after_seconds(*v);
  send_problem(res, req, p);
}

// GET /v1/jobs/{id}/frames.tar: the finished frames of an animation as one archive.
void get_frames_archive(const RouteContext& c, const httplib::Request& req,
                        httplib::Response& res) {
  const std::string id = req.matches[1];
  const auto variant = result_variant(req);
  if (const auto* p = std::get_if<Problem>(&variant)) return send_problem(res, req, *p);
  const std::string& which = std::get<std::string>(variant);
  // EXR unless asked: an archive of frames is for a compositor or an encoder, and EXR is the
  // linear, lossless one. Accept is not consulted: it names the archive's type, not the frames'.
  const auto format = negotiate_image_format(
      param_value(req, "format").value_or("exr"), std::nullopt);
  if (const auto* p = std::get_if<Problem>(&format)) return send_problem(res, req, *p);
  const ImageFormat f = std::get<ImageFormat>(format);
  if (auto p = blender_layout_conflict(which, f)) return send_problem(res, req, *p);
  const auto v = c.jobs.view(id);
  if (!v) return send_problem(res, req, status_problem(404, "no job " + id));
  const JobRecord& r = v->record;
  if (r.frame_count() == 0) {
    Problem p = make_problem(404, "not-an-animation", "Not an animation",
                             "job " + id + " renders a still (its scene has no \"animation\"); "
                             "its image is " + job_path(id) + "/result");
    return send_problem(res, req, p);
  }
  // Succeeded: every frame. Cancelled or failed: the frames it finished (the archive holds
  // what there is). Still running: not yet, as /result (the frames so far are each at ?frame=).
  if (!is_finished(r.state) || r.frames_done == 0) {
    Problem p = make_problem(
        409, "result-not-ready", "Result not ready",
        "job " + id + " is " + to_string(r.state) + " with " + std::to_string(r.frames_done) +
            " of " + std::to_string(r.frame_count()) + " frames done" +
            (is_finished(r.state) ? "; it has no frames" : "; poll the job and retry"));
    p.extensions["state"] = to_string(r.state);
    p.extensions["frames"] = {{"first", r.frame_first}, {"last", r.frame_last}, {"done", r.frames_done}};
    if (!is_finished(r.state)) p.retry_after_seconds = retry_after_seconds(*v);
    return send_problem(res, req, p);
  }
  const std::string key = which.empty() ? std::string(file_extension(f))
                                        : which + "." + file_extension(f);
  // Succeeded: every frame. Otherwise the done ones, which on a farm need not be the first
  // frames_done (frames finish in any order there).
  std::vector<int> frames;
  for (int i = r.frame_first; i <= r.frame_last; ++i) {
    if (r.state == JobState::kSucceeded || c.jobs.open_result(id, "png", i)) frames.push_back(i);
  }
  auto plan = plan_frame_archive(c.jobs, id, key, frames, frame_digits(r.frame_first, r.frame_last),
                                 std::int64_t(r.finished_at));
  if (!plan) {
    if (c.jobs.open_result(id, "png", r.frame_first) && !which.empty()) {
      Problem p = make_problem(404, "layer-not-rendered", "Layer not rendered",
                               which == "blender"
                                   ? "job " + id + " has no output layers, so no Blender layout"
                                   : "job " + id + " did not ask for the " + which +
                                         " layer; list it in the scene's render.outputs");
      p.extensions["layer"] = which;
      return send_problem(res, req, p);
    }
    return send_problem(res, req, status_problem(404, "the frames of job " + id + " are gone"));
  }
  const auto archive = std::make_shared<const FrameArchive>(std::move(*plan));
  std::string tag = key;
  std::replace(tag.begin(), tag.end(), '.', '-');
  res.set_header("Content-Disposition",
                 "attachment; filename=\"" + id + ".frames" +
                     (which.empty() ? "" : "." + which) + "." + file_extension(f) + ".tar\"");
  // The frames of a finished job never change: the count names the archive's content.
  res.set_header("ETag", "\"" + id + "-frames-" + std::to_string(r.frames_done) + "-" + tag + "\"");
  res.set_header("Cache-Control", "private, max-age=3600");
  res.set_header("Accept-Ranges", "bytes");
  res.set_header("Penumbra-Frames", std::to_string(archive->entries.size()));
  const RangeDecision d = decide_range(header_value(req, "Range"), archive->size);
  if (d.kind == RangeDecision::Kind::kUnsatisfiable) {
    res.set_header("Content-Range", "bytes */" + std::to_string(archive->size));
    Problem p = make_problem(416, "range-not-satisfiable", "Range Not Satisfiable",
                             "the range lies outside the " + std::to_string(archive->size) +
                                 "-byte archive");
    p.extensions["size"] = archive->size;
    return send_problem(res, req, p);
  }
  std::uint64_t first = 0, length = archive->size;
  if (d.kind == RangeDecision::Kind::kPartial) {
    first = d.first;
    length = d.last - d.first + 1;
    res.status = 206;
    res.set_header("Content-Range", "bytes " + std::to_string(d.first) + "-" +
                                        std::to_string(d.last) + "/" +
                                        std::to_string(archive->size));
  }
  const JobBackend& jobs = c.jobs;
  res.set_content_provider(
      std::size_t(length), "application/x-tar",
      [&jobs, archive, first, cursor = std::make_shared<FrameArchiveCursor>()](
          size_t offset, size_t n, httplib::DataSink& sink) {
        std::string chunk;
        if (!read_frame_archive(jobs, *archive, *cursor, first + offset,
                                std::min<std::size_t>(n, 1 << 16), chunk) ||
            chunk.empty())
          return false;  // a frame vanished (the job was deleted): the answer is cut short
        sink.write(chunk.data(), chunk.size());
        return true;
      });
}

}  // namespace

void add_result_routes(httplib::Server& s, const RouteContext& c) {
  s.Get(kResultRoute,
        [&c](const httplib::Request& req, httplib::Response& res) { get_result(c, req, res); });
  s.Get(kFramesArchiveRoute, [&c](const httplib::Request& req, httplib::Response& res) {
    get_frames_archive(c, req, res);
  });
}

}  // namespace penumbra::server
