#include "server/farm/farm_render.h"

#include <algorithm>
#include <chrono>

#include "api/animation_parser.h"
#include "api/diagnostics.h"
#include "api/job_submission.h"

namespace penumbra::server {

RenderOutcome render_farm_piece(const std::string& scene_json, const RenderJobOptions& options,
                                JobRuntime& runtime, const TaskPiece& piece) {
  RenderOutcome out;
  // Validated at submission; again here because this worker may run with tighter limits.
  const api::JobSubmission submission =
      api::parse_job_submission(scene_json, options.limits.max_json_depth,
                                api::ManifestLimits{.max_files = 1 << 30});
  api::LoadResult loaded =
      submission.ok() ? api::load_scene(submission.scene_text, options.limits, {}, options.assets)
                      : api::LoadResult{std::nullopt, submission.kind, submission.errors, {}};
  if (!loaded.ok()) {
    out.error = "the scene is no longer valid under this server's limits: " +
                loaded.errors.front().to_string();
    return out;
  }
  if (piece.frame) {
    api::Diagnostics diag;
    if (!api::select_frame(*loaded.request, *piece.frame, diag)) {
      const auto errors = diag.take_errors();
      out.error = "frame " + std::to_string(*piece.frame) + ": " +
                  (errors.empty() ? std::string("not in the animation") : errors.front().to_string());
      return out;
    }
  }
  RenderSettings settings = loaded.request->settings;
  settings.threads = options.threads;
  if (options.max_render_seconds > 0)
    settings.time_limit = settings.time_limit > 0
                              ? std::min(settings.time_limit, options.max_render_seconds)
                              : options.max_render_seconds;
  if (piece.window) {
    if (!piece.window->fits(settings.width, settings.height)) {
      out.error = "the task's window does not fit the scene's image";
      return out;
    }
    settings.window = *piece.window;
  }
  out.settings = settings;
  if (piece.window && settings.denoise) {
    settings.denoise = false;
    settings.outputs |= uint32_t(kOutputAlbedo | kOutputNormal);
  }

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
    // As run_render_job: the limit less the time spent so far and the time to store the images.
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - options.started).count();
    const std::uint64_t pixels =
        settings.window ? std::uint64_t(settings.window->pixel_count())
                        : std::uint64_t(settings.width) * std::uint64_t(settings.height);
    settings.time_limit = std::max(1e-3, settings.time_limit - spent - finish_seconds_estimate(pixels));
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

}  // namespace penumbra::server
