#include "server/farm/farm_render.h"

#include "api/animation_parser.h"
#include "api/diagnostics.h"

namespace penumbra::server {

std::shared_ptr<const PreparedScene> prepare_piece_scene(const std::string& scene_json,
                                                         const RenderJobOptions& options,
                                                         const TaskPiece& piece,
                                                         std::string& error) {
  api::LoadResult loaded = load_job_request(scene_json, options, error);
  if (!loaded.ok()) return nullptr;
  api::SceneRequest& request = *loaded.request;
  if (piece.frame) {
    api::Diagnostics diag;
    if (!api::select_frame(request, *piece.frame, diag)) {
      const auto errors = diag.take_errors();
      error = "frame " + std::to_string(*piece.frame) + ": " +
              (errors.empty() ? std::string("not in the animation") : errors.front().to_string());
      return nullptr;
    }
  }
  BuiltScene built = build_request_scene(request);
  if (!built.scene) {
    error = std::move(built.error);
    return nullptr;
  }
  // The parsed input (meshes, images) goes with `loaded` here: the built scene holds what it
  // renders from, so a cached scene keeps one copy of the geometry, Embree's.
  auto prepared = std::make_shared<PreparedScene>();
  prepared->settings = request.settings;
  prepared->scene = std::move(built.scene);
  prepared->build_seconds = built.build_seconds;
  return prepared;
}

RenderOutcome render_farm_piece(const PreparedScene& scene, bool built_here,
                                const RenderJobOptions& options, JobRuntime& runtime,
                                const TaskPiece& piece) {
  RenderOutcome out;
  RenderSettings settings = scene.settings;
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
  out = render_built_scene(*scene.scene, settings, options, options.started, runtime, {});
  out.build_seconds = built_here ? scene.build_seconds : 0.0;
  out.scene_reused = !built_here;
  // What the merge must produce: the job's own denoising and layers.
  out.settings.denoise = denoise;
  out.settings.outputs = outputs;
  return out;
}

}  // namespace penumbra::server
