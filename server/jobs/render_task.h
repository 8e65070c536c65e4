#pragma once
// Renders one job: scene JSON -> validated request -> Embree scene -> progressive render.
// Called on the service's own worker threads, never on HTTP threads.
#include <chrono>
#include <string>

#include "api/scene_loader.h"
#include "renderer/core/image.h"
#include "renderer/io/image_io.h"
#include "renderer/render/render.h"
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
  std::string error;  // when failed
};

// The job's "stats" object (render statistics, denoising) as JSON text.
std::string render_stats_json(const RenderOutcome& outcome, int threads);
// The metadata written into a job's result images.
ImageMetadata result_metadata(const std::string& job_id, const RenderOutcome& outcome);

RenderOutcome run_render_job(const std::string& scene_json, const RenderJobOptions& options,
                             JobRuntime& runtime);

}  // namespace penumbra::server
