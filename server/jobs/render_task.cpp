#include "server/jobs/render_task.h"

#include <algorithm>
#include <chrono>

#include <nlohmann/json.hpp>

#include "api/animation_parser.h"
#include "api/job_submission.h"
#include "api/version.h"

namespace {
// What follows the sampling, per pixel: resolving the film and its variance, encoding the EXR and
// the PNG, writing both with fsync. Measured 4.5e-8 s (0.76 s for 4096 x 4096: 0.53 s resolve,
// 0.23 s encode and write) on the 2-core machine, about doubled for a loaded machine.
constexpr double kFinishSecondsPerPixel = 1.0e-7;
}  // namespace

namespace penumbra::server {

double finish_seconds_estimate(std::uint64_t pixels) {
  return 0.05 + double(pixels) * kFinishSecondsPerPixel;
}

namespace {

// Where a frame's progress lies within the whole job: frames before it are done, frames after it
// are to come (their time estimated from the frames this attempt has rendered, else this one's).
struct FrameProgressMap {
  int frames = 1;           // in the job
  int done_before = 0;      // finished before this frame (earlier attempts included)
  int remaining_after = 0;  // frames after this one
  double mean_frame_seconds = 0;  // of the frames this attempt finished; 0 = none yet
  RenderProgress operator()(const RenderProgress& p) const {
    if (frames <= 1) return p;
    RenderProgress out = p;
    out.fraction = (double(done_before) + p.fraction) / double(frames);
    out.samples_done = uint64_t(done_before) * p.samples_total + p.samples_done;
    out.samples_total = uint64_t(frames) * p.samples_total;
    const double per_frame =
        mean_frame_seconds > 0 ? mean_frame_seconds : p.elapsed_seconds + p.eta_seconds;
    out.eta_seconds = p.eta_seconds + double(remaining_after) * per_frame;
    return out;
  }
};

}  // namespace

BuiltScene build_request_scene(const api::SceneRequest& request) {
  BuiltScene out;
  const auto build_start = std::chrono::steady_clock::now();
  try {
    std::unique_ptr<Scene> scene = Scene::build(request.scene);
    scene->prepare_sampling(request.settings.integrator);
    out.scene = std::move(scene);
  } catch (const SceneBuildError& e) {
    out.error = std::string("scene build failed: ") + e.what();
    return out;
  }
  out.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
  return out;
}

RenderOutcome render_built_scene(const Scene& scene, const RenderSettings& request_settings,
                                 const RenderJobOptions& options,
                                 std::chrono::steady_clock::time_point started,
                                 JobRuntime& runtime, const ProgressMap& progress_map) {
  const ProgressMap map =
      progress_map ? progress_map : ProgressMap([](const RenderProgress& p) { return p; });
  RenderOutcome out;
  RenderSettings settings = request_settings;
  settings.threads = options.threads;
  if (options.max_render_seconds > 0)
    settings.time_limit = settings.time_limit > 0
                              ? std::min(settings.time_limit, options.max_render_seconds)
                              : options.max_render_seconds;
  out.settings = settings;
  if (settings.time_limit > 0) {
    // What is left for sampling: the limit less the time spent so far (queue to running, scene
    // read and built) and the time the images will take to encode and store. The render loop
    // then stops within one tile of its own limit (renderer/render/render.cpp).
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const double finish = finish_seconds_estimate(
        settings.window ? std::uint64_t(settings.window->pixel_count())
                        : std::uint64_t(settings.width) * std::uint64_t(settings.height));
    settings.time_limit = std::max(1e-3, settings.time_limit - spent - finish);
  }
  if (runtime.cancel_flag()->load()) {
    out.kind = RenderOutcome::Kind::kStopped;
    return out;
  }

  RenderControl control;
  control.cancel = runtime.cancel_flag();
  control.on_progress = [&runtime, &map](const RenderProgress& p) { runtime.set_progress(map(p)); };
  control.on_pass = [&runtime, &map](const Image& image, const RenderProgress& p) {
    runtime.set_preview(image);
    runtime.set_progress(map(p));
  };
  RenderResult result = render(scene, settings, control);
  out.stats = result.stats;
  out.image = std::move(result.image);
  out.layers = std::move(result.layers);
  out.kind =
      result.stats.cancelled ? RenderOutcome::Kind::kStopped : RenderOutcome::Kind::kSucceeded;
  return out;
}

RenderOutcome render_request(const api::SceneRequest& request, const RenderJobOptions& options,
                             std::chrono::steady_clock::time_point started, JobRuntime& runtime,
                             const ProgressMap& progress_map) {
  BuiltScene built = build_request_scene(request);
  if (!built.scene) {
    RenderOutcome out;
    out.settings = request.settings;
    out.settings.threads = options.threads;
    out.error = std::move(built.error);
    return out;
  }
  RenderOutcome out =
      render_built_scene(*built.scene, request.settings, options, started, runtime, progress_map);
  out.build_seconds = built.build_seconds;
  return out;
}

namespace {

// The job's statistics so far plus one more frame's: sums, and the spp extremes and mean.
void add_frame_stats(RenderOutcome& job, const RenderOutcome& frame) {
  RenderStats& s = job.stats;
  const RenderStats& f = frame.stats;
  const int n = job.frames_rendered;  // frames already in `job`
  s.seconds += f.seconds;
  s.rays += f.rays;
  s.camera_samples += f.camera_samples;
  s.spp_min = n == 0 ? f.spp_min : std::min(s.spp_min, f.spp_min);
  s.spp_max = std::max(s.spp_max, f.spp_max);
  s.spp_mean = (s.spp_mean * n + f.spp_mean) / double(n + 1);
  s.stopped_by_time_limit = s.stopped_by_time_limit || f.stopped_by_time_limit;
  s.nonfinite_samples += f.nonfinite_samples;
  s.denoised = n == 0 ? f.denoised : s.denoised && f.denoised;
  s.denoise_seconds += f.denoise_seconds;
  if (s.denoise_error.empty()) s.denoise_error = f.denoise_error;
  job.build_seconds += frame.build_seconds;
  job.settings = frame.settings;
}

}  // namespace

api::LoadResult load_job_request(const std::string& scene_json, const RenderJobOptions& options,
                                 std::string& error) {
  // Validated at submission; validated again because the server may have restarted with
  // tighter limits since.
  // The stored text is the body as submitted: a bare scene or {"scene": ..., "assets": ...}.
  const api::JobSubmission submission =
      api::parse_job_submission(scene_json, options.limits.max_json_depth, api::ManifestLimits{
                                    .max_files = 1 << 30});
  api::LoadResult loaded =
      submission.ok() ? api::load_scene(submission.scene_text, options.limits, {}, options.assets)
                      : api::LoadResult{std::nullopt, submission.kind, submission.errors, {}};
  if (!loaded.ok())
    error = "the scene is no longer valid under this server's limits: " +
            loaded.errors.front().to_string();
  return loaded;
}

RenderOutcome run_render_job(const std::string& scene_json, const RenderJobOptions& options,
                             JobRuntime& runtime) {
  RenderOutcome out;
  api::LoadResult loaded = load_job_request(scene_json, options, out.error);
  if (!loaded.ok()) return out;
  api::SceneRequest& request = *loaded.request;
  // A still, or a caller that stores no frames (no on_frame: the farm's whole-job task, until
  // it has frame tasks): one image, an animation's first frame (load_scene set its shutter).
  if (!request.animation || !options.on_frame)
    return render_request(request, options, options.started, runtime, {});

  // An animation: its frames one after another. Not several at once: the renderer already
  // spreads one frame over all of the job's threads (tiles), so concurrent frames would only
  // share the same cores while each holding a scene and a film; and in order, the frames done
  // are always a prefix of the range, so one number (frames_done) says where a restart resumes.
  const api::Animation animation = *request.animation;
  out.animation = true;
  out.kind = RenderOutcome::Kind::kSucceeded;
  const int first = int(animation.first_frame), last = int(animation.last_frame);
  const int from = std::max(first, options.resume_frame.value_or(first));
  FrameProgressMap map;
  map.frames = last - first + 1;
  for (int frame = from; frame <= last; ++frame) {
    api::Diagnostics diag;
    if (!api::select_frame(request, frame, diag)) {
      out.kind = RenderOutcome::Kind::kFailed;
      out.error = diag.take_errors().front().to_string();
      return out;
    }
    map.done_before = frame - first;
    map.remaining_after = last - frame;
    map.mean_frame_seconds = out.frames_rendered > 0
                                 ? (out.stats.seconds + out.build_seconds) / out.frames_rendered
                                 : 0.0;
    runtime.clear_preview();
    // A time limit (the scene's, the server's) is per frame, as `penumbra render --frames`.
    RenderOutcome frame_out =
        render_request(request, options, std::chrono::steady_clock::now(), runtime, map);
    frame_out.frame = frame;
    if (frame_out.kind != RenderOutcome::Kind::kSucceeded) {
      // Stopped (cancel, shutdown) or failed mid-animation: the frames before stay stored.
      add_frame_stats(out, frame_out);
      out.kind = frame_out.kind;
      out.error = frame_out.error;
      return out;
    }
    if (options.on_frame) options.on_frame(frame, frame_out);
    add_frame_stats(out, frame_out);
    ++out.frames_rendered;
    if (!out.first_frame_rendered) out.first_frame_rendered = frame;
  }
  return out;
}

std::string render_stats_json(const RenderOutcome& o, int threads) {
  const RenderStats& s = o.stats;
  nlohmann::ordered_json j{{"seconds", s.seconds},
                                {"build_seconds", o.build_seconds},
                                {"rays", s.rays},
                                {"mrays_per_second", s.mrays_per_second()},
                                {"spp_mean", s.spp_mean},
                                {"spp_min", s.spp_min},
                                {"spp_max", s.spp_max},
                                {"camera_samples", s.camera_samples},
                                {"stopped_by_time_limit", s.stopped_by_time_limit},
                                {"threads", threads}};
  if (o.scene_reused) j["scene_reused"] = *o.scene_reused;
  // An animation: how many frames this attempt rendered, and from which (the rest, if any, were
  // rendered by an earlier attempt and kept); the numbers above add up those frames.
  if (o.animation) {
    j["frames_rendered"] = o.frames_rendered;
    j["first_frame_rendered"] =
        o.first_frame_rendered ? nlohmann::ordered_json(*o.first_frame_rendered) : nullptr;
  }
  // render.denoise: whether the result is denoised, and if not, why (the job still succeeds).
  if (s.denoised || !s.denoise_error.empty()) {
    j["denoised"] = s.denoised;
    j["denoise_seconds"] = s.denoise_seconds;
    if (!s.denoise_error.empty()) j["denoise_error"] = s.denoise_error;
  }
  return j.dump();
}

ImageMetadata result_metadata(const std::string& job_id, const RenderOutcome& o) {
  ImageMetadata meta = {
      {"penumbra:job", job_id},
      {"penumbra:spp", std::to_string(o.settings.spp)},
      {"penumbra:spp_mean", std::to_string(o.stats.spp_mean)},
      {"penumbra:render_seconds", std::to_string(o.stats.seconds)},
      {"penumbra:seed", std::to_string(o.settings.seed)},
      {"Software", api::kSoftwareName},
  };
  if (o.frame) meta.push_back({"penumbra:frame", std::to_string(*o.frame)});  // as the CLI's
  return meta;
}

}  // namespace penumbra::server
