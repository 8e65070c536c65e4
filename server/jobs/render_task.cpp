#include "server/jobs/render_task.h"

#include <algorithm>
#include <chrono>

#include <nlohmann/json.hpp>

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

RenderOutcome run_render_job(const std::string& scene_json, const RenderJobOptions& options,
                             JobRuntime& runtime) {
  RenderOutcome out;
  // Validated at submission; validated again because the server may have restarted with
  // tighter limits since.
  // The stored text is the body as submitted: a bare scene or {"scene": ..., "assets": ...}.
  const api::JobSubmission submission =
      api::parse_job_submission(scene_json, options.limits.max_json_depth, api::ManifestLimits{
                                    .max_files = 1 << 30});
  api::LoadResult loaded =
      submission.ok() ? api::load_scene(submission.scene_text, options.limits, {}, options.assets)
                      : api::LoadResult{std::nullopt, submission.kind, submission.errors, {}};
  if (!loaded.ok()) {
    out.error = "the scene is no longer valid under this server's limits: " +
                loaded.errors.front().to_string();
    return out;
  }
  RenderSettings settings = loaded.request->settings;
  settings.threads = options.threads;
  if (options.max_render_seconds > 0)
    settings.time_limit = settings.time_limit > 0
                              ? std::min(settings.time_limit, options.max_render_seconds)
                              : options.max_render_seconds;
  out.settings = settings;

  const auto build_start = std::chrono::steady_clock::now();
  std::unique_ptr<Scene> scene;
  try {
    scene = Scene::build(loaded.request->scene);
  } catch (const SceneBuildError& e) {
    out.error = std::string("scene build failed: ") + e.what();
    return out;
  }
  out.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
  if (settings.time_limit > 0) {
    // What is left for sampling: the limit less the time spent so far (queue to running, scene
    // read and built) and the time the images will take to encode and store. The render loop
    // then stops within one tile of its own limit (renderer/render/render.cpp).
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - options.started).count();
    const double finish =
        finish_seconds_estimate(std::uint64_t(settings.width) * std::uint64_t(settings.height));
    settings.time_limit = std::max(1e-3, settings.time_limit - spent - finish);
  }
  if (runtime.cancel_flag()->load()) {
    out.kind = RenderOutcome::Kind::kStopped;
    return out;
  }

  RenderControl control;
  control.cancel = runtime.cancel_flag();
  control.on_progress = [&runtime](const RenderProgress& p) { runtime.set_progress(p); };
  control.on_pass = [&runtime](const Image& image, const RenderProgress& p) {
    runtime.set_preview(image);
    runtime.set_progress(p);
  };
  RenderResult result = render(*scene, settings, control);
  out.stats = result.stats;
  out.image = std::move(result.image);
  out.layers = std::move(result.layers);
  out.kind =
      result.stats.cancelled ? RenderOutcome::Kind::kStopped : RenderOutcome::Kind::kSucceeded;
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
  // render.denoise: whether the result is denoised, and if not, why (the job still succeeds).
  if (s.denoised || !s.denoise_error.empty()) {
    j["denoised"] = s.denoised;
    j["denoise_seconds"] = s.denoise_seconds;
    if (!s.denoise_error.empty()) j["denoise_error"] = s.denoise_error;
  }
  return j.dump();
}

ImageMetadata result_metadata(const std::string& job_id, const RenderOutcome& o) {
  return {
      {"penumbra:job", job_id},
      {"penumbra:spp", std::to_string(o.settings.spp)},
      {"penumbra:spp_mean", std::to_string(o.stats.spp_mean)},
      {"penumbra:render_seconds", std::to_string(o.stats.seconds)},
      {"penumbra:seed", std::to_string(o.settings.seed)},
      {"Software", api::kSoftwareName},
  };
}

}  // namespace penumbra::server
