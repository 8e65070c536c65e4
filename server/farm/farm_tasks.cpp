#include "server/farm/farm_tasks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "api/diagnostics.h"
#include "api/job_submission.h"
#include "api/json_document.h"
#include "server/storage/job_record.h"

namespace penumbra::server {
namespace fs = std::filesystem;

TaskPiece task_piece_from_params(const std::string& params_json) {
  TaskPiece piece;
  const nlohmann::json j = nlohmann::json::parse(params_json, nullptr, false);
  if (!j.is_object()) return piece;
  if (const auto f = j.find("frame"); f != j.end() && f->is_number_integer())
    piece.frame = f->get<int64_t>();
  if (const auto w = j.find("window"); w != j.end() && w->is_array() && w->size() == 4) {
    bool ints = true;
    for (const auto& v : *w) ints = ints && v.is_number_integer();
    if (ints) piece.window = PixelWindow{(*w)[0].get<int>(), (*w)[1].get<int>(),
                                         (*w)[2].get<int>(), (*w)[3].get<int>()};
  }
  return piece;
}

std::string task_params_json(const TaskPiece& piece) {
  nlohmann::json j = nlohmann::json::object();
  if (piece.frame) j["frame"] = *piece.frame;
  if (piece.window)
    j["window"] = {piece.window->x0, piece.window->y0, piece.window->x1, piece.window->y1};
  return j.dump();
}

std::vector<PixelWindow> tile_windows(int width, int height, int64_t tile_pixels) {
  const int64_t pixels = int64_t(width) * int64_t(height);
  if (width <= 0 || height <= 0 || tile_pixels <= 0 || pixels <= tile_pixels) return {};
  const int64_t wanted = (pixels + tile_pixels - 1) / tile_pixels;
  // Square tiles of side s = sqrt(pixels / wanted) make width / s columns.
  const double columns_exact = std::sqrt(double(wanted) * double(width) / double(height));
  // At most `wanted` columns: a frame thinner than a square tile gets strips, not slivers.
  const int columns =
      int(std::clamp<int64_t>(std::llround(columns_exact), 1, std::min<int64_t>(width, wanted)));
  const int rows = int(std::clamp<int64_t>((wanted + columns - 1) / columns, 1, height));
  std::vector<PixelWindow> out;
  out.reserve(std::size_t(columns) * std::size_t(rows));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c)
      out.push_back({int(int64_t(c) * width / columns), int(int64_t(r) * height / rows),
                     int(int64_t(c + 1) * width / columns), int(int64_t(r + 1) * height / rows)});
  return out;
}

JobShape read_job_shape(const std::string& scene_json, int max_json_depth) {
  JobShape shape;
  const api::JobSubmission submission = api::parse_job_submission(
      scene_json, max_json_depth, api::ManifestLimits{.max_files = 1 << 30});
  if (!submission.ok()) return shape;
  api::Diagnostics diag;
  const api::JsonDocument document =
      api::parse_json_document(submission.scene_text, max_json_depth, diag);
  if (!document.value || !document.value->is_object()) return shape;
  const nlohmann::json& scene = *document.value;
  // The scene was validated by the loader before this: the members have their checked types.
  if (const auto a = scene.find("animation"); a != scene.end() && a->is_object()) {
    const auto frames = a->find("frames");
    if (frames != a->end() && frames->is_array() && frames->size() == 2 &&
        (*frames)[0].is_number_integer() && (*frames)[1].is_number_integer())
      shape.frames = {(*frames)[0].get<int64_t>(), (*frames)[1].get<int64_t>()};
  }
  if (const auto r = scene.find("render"); r != scene.end() && r->is_object()) {
    if (r->contains("window")) shape.splittable = false;
    if (const auto t = r->find("time_limit"); t != r->end() && t->is_number() && t->get<double>() > 0)
      shape.splittable = false;
    // Path reuse mixes a pixel's paths with its block's (renderer/render/path_reuse.h): a window
    // cut through a block would give its pixels other values than the whole frame's.
    if (const auto p = r->find("path_reuse");
        p != r->end() && p->is_number_integer() && p->get<int64_t>() > 1)
      shape.splittable = false;
  }
  return shape;
}

namespace {
void remove_with_prefix(const fs::path& dir, const std::string& prefix) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) == 0) {
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
}
}  // namespace

void remove_job_files(const std::string& data_dir, const std::string& job_id) {
  if (!is_valid_job_id(job_id)) return;
  remove_with_prefix(fs::path(data_dir) / "results", job_id + ".");
  remove_with_prefix(fs::path(data_dir) / "previews", job_id + ".");
}

void remove_attempt_files(const std::string& data_dir, const std::string& job_id,
                          const std::string& token) {
  if (!is_valid_job_id(job_id) || token.empty()) return;
  remove_with_prefix(fs::path(data_dir) / "results", job_id + "." + token + ".");
}

std::string tile_preview_path(const std::string& data_dir, const std::string& job_id,
                              const PixelWindow& w) {
  char name[128];
  std::snprintf(name, sizeof name, ".w%d_%d_%d_%d.exr", w.x0, w.y0, w.x1, w.y1);
  return (fs::path(data_dir) / "previews" / (job_id + name)).string();
}

std::vector<std::pair<PixelWindow, std::string>> tile_previews(const std::string& data_dir,
                                                               const std::string& job_id) {
  std::vector<std::pair<PixelWindow, std::string>> out;
  if (!is_valid_job_id(job_id)) return out;
  const std::string prefix = job_id + ".w";
  std::error_code ec;
  for (fs::directory_iterator it(fs::path(data_dir) / "previews", ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    PixelWindow w;
    char tail[8] = {};
    if (std::sscanf(name.c_str() + prefix.size(), "%d_%d_%d_%d%7s", &w.x0, &w.y0, &w.x1, &w.y1,
                    tail) == 5 &&
        std::string(tail) == ".exr")
      out.emplace_back(w, it->path().string());
  }
  return out;
}

}  // namespace penumbra::server
