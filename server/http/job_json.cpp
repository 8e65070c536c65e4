#include "server/http/job_json.h"

#include <algorithm>
#include <cmath>
#include <ctime>

namespace penumbra::server {

std::string job_path(const std::string& id) { return "/v1/jobs/" + id; }

double retry_after_seconds(const JobView& v) {
  if (v.progress && v.progress->fraction > 0) return std::clamp(v.progress->eta_seconds, 1.0, 10.0);
  return v.record.state == JobState::kQueued ? 2.0 : 1.0;
}

std::string rfc3339(double t) {
  const std::time_t seconds = std::time_t(std::floor(t));
  const int millis = std::min(999, int((t - std::floor(t)) * 1000));
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
  return buf;
}

nlohmann::ordered_json notify_json(const JobRecord::Notify& n) {
  using json = nlohmann::ordered_json;
  auto time_or_null = [](double t) { return t > 0 ? json(rfc3339(t)) : json(nullptr); };
  // Never the secret.
  const char* state = n.delivered_at > 0 ? "delivered"
                      : n.gave_up_at > 0 ? "failed"
                      : n.attempts > 0   ? "retrying"
                                         : "waiting";
  return {{"url", n.url},
          {"delivery", state},
          {"attempts", n.attempts},
          {"last_status", n.last_status > 0 ? json(n.last_status) : json(nullptr)},
          {"last_error", n.last_error.empty() ? json(nullptr) : json(n.last_error)},
          {"last_attempt_at", time_or_null(n.last_attempt_at)},
          {"next_attempt_at", time_or_null(n.next_attempt_at)},
          {"delivered_at", time_or_null(n.delivered_at)}};
}

std::string webhook_body(const JobRecord& r) {
  // What GET /v1/jobs/{id} answers for the finished job, with notify reduced to its url: the
  // body (and so its signature) is the same on every retry and after a restart.
  JobRecord copy = r;
  const std::string url = copy.notify.url;
  copy.notify = {};
  nlohmann::ordered_json j = job_json(JobView{copy, std::nullopt, std::nullopt, false, std::nullopt});
  j["notify"] = {{"url", url}};
  return j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

nlohmann::ordered_json job_json(const JobView& v) {
  using json = nlohmann::ordered_json;
  const JobRecord& r = v.record;
  auto time_or_null = [](double t) { return t > 0 ? json(rfc3339(t)) : json(nullptr); };
  json j = {{"id", r.id}, {"state", to_string(r.state)}};
  double progress = 0;
  // samples_total is width x height x spp, except while an adaptive render (noise_threshold)
  // runs: then it is the renderer's current estimate, and once it succeeds, what it took.
  uint64_t samples_done = 0, samples_total = r.samples_total;
  json eta = nullptr;
  if (r.state == JobState::kSucceeded) {
    progress = 1;
    samples_done = r.samples_total;
  }
  if (v.progress) {
    progress = v.progress->fraction;
    samples_done = v.progress->samples_done;
    if (v.progress->samples_total > 0) samples_total = v.progress->samples_total;
    if (v.progress->fraction > 0) eta = v.progress->eta_seconds;
  }
  json stats = nullptr;
  if (!r.stats_json.empty()) {
    stats = json::parse(r.stats_json);
    if (r.state == JobState::kSucceeded || r.state == JobState::kCancelled)
      samples_done = stats.value("camera_samples", samples_done);
    if (r.state == JobState::kSucceeded) samples_total = samples_done;
    if (r.state == JobState::kCancelled && r.samples_total > 0)
      progress = std::min(1.0, double(samples_done) / double(r.samples_total));  // how far it got
  }
  const int frame_count = r.frame_count();
  if (frame_count > 0 && !v.progress) {
    // An animation not rendering now: the frames it finished are what it has (a running one's
    // progress already counts frames, server/jobs/render_task.cpp).
    progress = r.state == JobState::kSucceeded ? 1.0 : double(r.frames_done) / frame_count;
    samples_done = r.samples_total / uint64_t(frame_count) * uint64_t(r.frames_done);
    samples_total = r.samples_total;
  }
  j["progress"] = progress;
  j["samples_done"] = samples_done;
  j["samples_total"] = samples_total;
  j["eta_seconds"] = eta;
  j["queue_position"] = v.queue_position ? json(*v.queue_position) : json(nullptr);
  j["priority"] = r.priority;
  if (v.stop_requested) j["cancel_requested"] = true;
  j["created_at"] = time_or_null(r.created_at);
  j["started_at"] = time_or_null(r.started_at);
  j["finished_at"] = time_or_null(r.finished_at);
  j["attempts"] = r.attempts;
  j["render"] = {{"width", r.width}, {"height", r.height}, {"spp", r.spp}};
  if (frame_count > 0) {
    // The animation's frames (both ends rendered) and how many are finished (at
    // /result?frame=N). While one node renders it, frame by frame in order, the frame under way
    // and how far it is; a farm renders several frames at once, in any order: no single current.
    json frames = {{"first", r.frame_first}, {"last", r.frame_last}, {"done", r.frames_done}};
    if (v.current_frame) {
      frames["current"] = *v.current_frame;
      frames["current_progress"] =
          v.progress ? std::clamp(v.progress->fraction * frame_count - r.frames_done, 0.0, 1.0)
                     : 0.0;
    }
    j["frames"] = frames;
  }
  // A render cut by its time limit says so at the top, with the samples per pixel it reached,
  // so a client need not read the stats to learn that the image is less converged than asked.
  if (stats.is_object() && stats.value("stopped_by_time_limit", false)) {
    j["stopped_early"] = "time_limit";
    j["spp_reached"] = stats.value("spp_mean", 0.0);
  }
  j["stats"] = stats;
  if (!r.error_json.empty()) j["error"] = json::parse(r.error_json);
  j["warnings"] = r.warnings_json.empty() ? json::array() : json::parse(r.warnings_json);
  if (!r.notify.url.empty()) j["notify"] = notify_json(r.notify);
  const std::string self = job_path(r.id);
  j["links"] = {{"self", self},
                {"result", self + "/result"},
                {"result_png", self + "/result?format=png"},
                {"result_exr", self + "/result?format=exr"},
                {"preview", self + "/result?preview=true"}};
  if (frame_count > 0) j["links"]["frames"] = self + "/frames.tar";
  return j;
}

}  // namespace penumbra::server
