#pragma once
// The tasks a farm job is made of (docs/scale-out.md, "Tasks"), decided once at submission:
//   job    the whole still, one task (a frame of --tile-pixels or fewer)
//   tile   a window of a large still (params {"window": [x0, y0, x1, y1]}); when the last one
//          commits, a "merge" task (params {}) is queued in the same transaction
//   frame  one frame of an animation (params {"frame": i})
// and where their files live on the shared volume.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "renderer/core/pixel_window.h"

namespace penumbra::server {

// What a task renders of its job's scene.
struct TaskPiece {
  std::optional<int64_t> frame;       // an animation's frame (api::select_frame)
  std::optional<PixelWindow> window;  // a window of the frame (RenderSettings::window)
};
// From tasks.params (written by plan_tasks); an empty piece for anything else.
TaskPiece task_piece_from_params(const std::string& params_json);
std::string task_params_json(const TaskPiece& piece);

// The windows a width x height frame is cut into: none (an empty list: one task renders it)
// when it has at most `tile_pixels` pixels; otherwise n = ceil(pixels / tile_pixels) windows or a
// few more (fewer than 2n) in a grid of columns x rows chosen so that each window is close to
// square (strips when the frame is thinner than a square tile), edges at
// floor(i * width / columns), every pixel in exactly one window.
std::vector<PixelWindow> tile_windows(int width, int height, int64_t tile_pixels);

// What the validated submission (scene or envelope) asks that decides its tasks.
struct JobShape {
  std::optional<std::pair<int64_t, int64_t>> frames;  // the animation's [first, last]
  // False when the scene renders a window already or has a time limit of its own (a limit is
  // for the whole render; tiles would each take it, docs/scale-out.md).
  bool splittable = true;
};
JobShape read_job_shape(const std::string& scene_json, int max_json_depth);

// The shared volume's files of a job: results/<job>.<token>.<key> of every attempt that wrote
// any (committed or not), and the previews/<job>.* of running tasks. Job ids are 24 hex digits
// (is_valid_job_id), so the prefix "<job>." names this job's files and nothing else.
void remove_job_files(const std::string& data_dir, const std::string& job_id);
// One attempt's files: results/<job>.<token>.*.
void remove_attempt_files(const std::string& data_dir, const std::string& job_id,
                          const std::string& token);

// The key (ResultStore format) of a tile's window EXR: beauty and layers, the frame as display
// window and the tile as data window, as `penumbra render --window` writes it.
inline constexpr const char* kTileResultKey = "tile.exr";

// A running tile's progressive image on the shared volume: previews/<job>.w<x0>_<y0>_<x1>_<y1>.exr,
// the window's pixels (an API node places every tile's in one frame).
std::string tile_preview_path(const std::string& data_dir, const std::string& job_id,
                              const PixelWindow& window);
// Every tile preview of the job, with its window.
std::vector<std::pair<PixelWindow, std::string>> tile_previews(const std::string& data_dir,
                                                               const std::string& job_id);

}  // namespace penumbra::server
