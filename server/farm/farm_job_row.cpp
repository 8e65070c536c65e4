#include "server/farm/farm_job_row.h"

#include <nlohmann/json.hpp>

namespace penumbra::server {

const char* const kJobColumns =
    "id, seq, state, idempotency_key, created_at, started_at, finished_at, attempts, width, "
    "height, spp, samples_total, stats_json, error_json, warnings_json, priority, "
    "cancel_requested, progress_json, result_token, version, frame_first, frame_last, frames_done";

JobRecord job_from_row(const PgRows& rows, int row) {
  JobRecord r;
  r.id = rows.value(row, "id");
  r.seq = rows.int_value(row, "seq");
  r.state = job_state_from_string(rows.value(row, "state")).value_or(JobState::kFailed);
  r.idempotency_key = rows.value(row, "idempotency_key");
  r.created_at = rows.double_value(row, "created_at");
  r.started_at = rows.double_value(row, "started_at");
  r.finished_at = rows.double_value(row, "finished_at");
  r.attempts = int(rows.int_value(row, "attempts"));
  r.width = int(rows.int_value(row, "width"));
  r.height = int(rows.int_value(row, "height"));
  r.spp = int(rows.int_value(row, "spp"));
  r.samples_total = uint64_t(rows.int_value(row, "samples_total"));
  r.stats_json = rows.value(row, "stats_json");
  r.error_json = rows.value(row, "error_json");
  r.warnings_json = rows.value(row, "warnings_json");
  r.priority = int(rows.int_value(row, "priority"));
  r.frame_first = int(rows.int_value(row, "frame_first"));
  r.frame_last = int(rows.int_value(row, "frame_last"));
  r.frames_done = int(rows.int_value(row, "frames_done"));
  return r;
}

std::optional<RenderProgress> progress_from_row(const PgRows& rows, int row) {
  const std::string text = rows.value(row, "progress_json");
  if (text.empty()) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) return std::nullopt;
  RenderProgress p;
  p.fraction = j.value("fraction", 0.0);
  p.samples_done = j.value("samples_done", uint64_t(0));
  p.samples_total = j.value("samples_total", uint64_t(0));
  p.elapsed_seconds = j.value("elapsed_seconds", 0.0);
  p.eta_seconds = j.value("eta_seconds", 0.0);
  p.passes_done = j.value("passes_done", 0);
  return p;
}

std::string progress_to_json(const RenderProgress& p) {
  return nlohmann::json{{"fraction", p.fraction},
                        {"samples_done", p.samples_done},
                        {"samples_total", p.samples_total},
                        {"elapsed_seconds", p.elapsed_seconds},
                        {"eta_seconds", p.eta_seconds},
                        {"passes_done", p.passes_done}}
      .dump();
}

}  // namespace penumbra::server
