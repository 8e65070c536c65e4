#pragma once
// Renders one farm task's piece of its job: a window of the still (a tile) or one frame of an
// animation (farm_tasks.h). The same steps as a single node's run_render_job (scene JSON ->
// validated request -> Embree scene -> progressive render), split in two so that a worker
// prepares a job's scene once for all of its tiles (scene_cache.h): the scene with its frame
// chosen (api::select_frame), then each piece rendered from it with its window
// (RenderSettings::window).
#include <memory>
#include <string>

#include "server/farm/farm_tasks.h"
#include "server/farm/scene_cache.h"
#include "server/jobs/render_task.h"

namespace penumbra::server {

// The job's scene as its pieces render it: read and validated under this server's limits, the
// piece's frame chosen, built. Null with `error` when it cannot be.
std::shared_ptr<const PreparedScene> prepare_piece_scene(const std::string& scene_json,
                                                         const RenderJobOptions& options,
                                                         const TaskPiece& piece, std::string& error);

// Renders the piece from its job's prepared scene. A tile of a job that asks for denoising
// renders without it (a window cannot be denoised alone: docs/animation-and-windows.md) but with
// the denoiser's guide layers, albedo and normal; the merge denoises the whole frame.
// outcome.settings keeps the job's own `denoise` and `outputs` (what the merge must produce),
// with the piece's window. `built_here`: this task prepared the scene (its build_seconds count
// for it; a task that reused it reports 0 and scene_reused).
RenderOutcome render_farm_piece(const PreparedScene& scene, bool built_here,
                                const RenderJobOptions& options, JobRuntime& runtime,
                                const TaskPiece& piece);

}  // namespace penumbra::server
