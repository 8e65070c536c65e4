#pragma once
// Renders one job: scene JSON -> validated request -> Embree scene -> progressive render; an
// animation renders each of its frames so, one after another (docs/animation-and-windows.md).
// Called on the service's own worker threads, never on HTTP threads.
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "api/scene_loader.h"
#include "renderer/core/image.h"
#include "renderer/io/image_io.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "server/jobs/job_runtime.h"

namespace penumbra::server {

struct RenderJobOptions {
  api::Limits limits;
  // The job's own folder of files (its manifest's hard links); empty root: the job names none.
  api::AssetFolder assets;
  int threads = 0;                // render threads for this job
  double max_render_seconds = 0;  // the server's budget per job; 0 = none
  // When the job started (marked running): a time limit counts from here, so reading the scene,
  // building it and writing the images fit in it too, not only the sampling.
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  // An animation (the scene's "animation"): frames are rendered one after another from
  // `resume_frame` (nullopt: the first) to the last, and each finished frame is handed to
  // `on_frame` before the next starts; it stores the frame durably (and throws if it cannot,
  // which fails the job). Frames before resume_frame were finished by an earlier attempt.
  // Without on_frame an animation renders its first frame only, as a still.
  std::optional<int> resume_frame;
  std::function<void(int frame, const struct RenderOutcome& frame_outcome)> on_frame;
};

// Seconds to encode and store a job's EXR and PNG of this many pixels, as measured here
// (docs/http-api.md, time limits) with a margin: kept back from the sampling budget.
double finish_seconds_estimate(std::uint64_t pixels);

struct RenderOutcome {
  enum class Kind { kSucceeded, kFailed, kStopped };
  Kind kind = Kind::kFailed;
  Image image;
  std::vector<ImageLayer> layers;  // the scene's render.outputs, in OutputLayerBit order
  RenderStats stats;
  RenderSettings settings;
  double build_seconds = 0;
  // A farm task's piece: whether it rendered a scene its worker had prepared for an earlier task
  // of the job (server/farm/scene_cache.h); unset elsewhere.
  std::optional<bool> scene_reused;
  std::string error;  // when failed
  // An animation: the frames were handed to on_frame as they finished (image and layers stay
  // empty); stats add up the frames this attempt rendered.
  bool animation = false;
  int frames_rendered = 0;                // by this attempt
  std::optional<int> first_frame_rendered;  // by this attempt
  std::optional<int> frame;                 // a single frame's outcome (on_frame): which
};

// The job's "stats" object (render statistics, denoising) as JSON text.
std::string render_stats_json(const RenderOutcome& outcome, int threads);
// The metadata written into a job's result images.
ImageMetadata result_metadata(const std::string& job_id, const RenderOutcome& outcome);

// Reads the stored job text (a bare scene or {"scene", "assets"}) under this server's limits;
// `error` says why when it is no longer valid.
api::LoadResult load_job_request(const std::string& scene_json, const RenderJobOptions& options,
                                 std::string& error);

// Maps one render's progress onto its job's (an animation's frame onto all frames); empty: as is.
using ProgressMap = std::function<RenderProgress(const RenderProgress&)>;

// A request's scene, built and with the sampling tables its integrator reads made (so they count
// as build time); `error` ("scene build failed: ...") when it cannot be built.
struct BuiltScene {
  std::unique_ptr<Scene> scene;
  double build_seconds = 0;
  std::string error;
};
BuiltScene build_request_scene(const api::SceneRequest& request);

// Renders a built scene with `settings` (the request's, or a piece's of them) and the job's
// threads and the server's budget; a time limit counts from `started` and keeps back the time to
// store the images. The scene is only read: several renders may share it.
RenderOutcome render_built_scene(const Scene& scene, const RenderSettings& settings,
                                 const RenderJobOptions& options,
                                 std::chrono::steady_clock::time_point started,
                                 JobRuntime& runtime, const ProgressMap& progress_map);

// Builds and renders one parsed request (a still, a chosen frame, a window) with the job's
// threads and the server's budget; a time limit counts from `started` and keeps back the time
// to store the images.
RenderOutcome render_request(const api::SceneRequest& request, const RenderJobOptions& options,
                             std::chrono::steady_clock::time_point started, JobRuntime& runtime,
                             const ProgressMap& progress_map);

RenderOutcome run_render_job(const std::string& scene_json, const RenderJobOptions& options,
                             JobRuntime& runtime);

}  // namespace penumbra::server
