#pragma once
// Renders one farm task's piece of its job: the whole still, a window of it, or one frame of an
// animation (farm_tasks.h). The same steps as a single node's run_render_job (scene JSON ->
// validated request -> Embree scene -> progressive render), with the piece chosen on the parsed
// request: api::select_frame for a frame, RenderSettings::window for a tile.
#include <string>

#include "server/farm/farm_tasks.h"
#include "server/jobs/render_task.h"

namespace penumbra::server {

// A tile of a job that asks for denoising renders without it (a window cannot be denoised
// alone: docs/animation-and-windows.md) but with the denoiser's guide layers, albedo and normal;
// the merge denoises the whole frame. outcome.settings keeps the job's own `denoise` and
// `outputs` (what the merge must produce), with the piece's window.
RenderOutcome render_farm_piece(const std::string& scene_json, const RenderJobOptions& options,
                                JobRuntime& runtime, const TaskPiece& piece);

}  // namespace penumbra::server
