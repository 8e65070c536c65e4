#include "server/farm/farm_render.h"

#include "api/animation_parser.h"
#include "api/diagnostics.h"

namespace penumbra::server {

RenderOutcome render_farm_piece(const std::string& scene_json, const RenderJobOptions& options,
                                JobRuntime& runtime, const TaskPiece& piece) {
  RenderOutcome out;
  api::LoadResult loaded = load_job_request(scene_json, options, out.error);
  if (!loaded.ok()) return out;
  api::SceneRequest& request = *loaded.request;
  if (piece.frame) {
    api::Diagnostics diag;
    if (!api::select_frame(request, *piece.frame, diag)) {
      const auto errors = diag.take_errors();
      out.error = "frame " + std::to_string(*piece.frame) + ": " +
                  (errors.empty() ? std::string("not in the animation") : errors.front().to_string());
      return out;
    }
  }
  RenderSettings& settings = request.settings;
  if (piece.window) {
    if (!piece.window->fits(settings.width, settings.height)) {
      out.error = "the task's window does not fit the scene's image";
      return out;
    }
    settings.window = *piece.window;
  }
  const bool denoise = settings.denoise;
  const uint32_t outputs = settings.outputs;
  if (piece.window && denoise) {
    settings.denoise = false;
    settings.outputs |= uint32_t(kOutputAlbedo | kOutputNormal);
  }
  out = render_request(request, options, options.started, runtime, {});
  // What the merge must produce: the job's own denoising and layers.
  out.settings.denoise = denoise;
  out.settings.outputs = outputs;
  return out;
}

}  // namespace penumbra::server
