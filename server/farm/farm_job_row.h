#pragma once
// A row of the farm's jobs table as a JobRecord, and the column list that reads it.
#include <optional>
#include <string>

#include "renderer/render/render.h"
#include "server/farm/pg_connection.h"
#include "server/storage/job_record.h"

namespace penumbra::server {

// The columns job_from_row() reads, for "SELECT <kJobColumns> FROM jobs ...".
extern const char* const kJobColumns;

JobRecord job_from_row(const PgRows& rows, int row);
// The progress a worker wrote at its last heartbeat (jobs.progress_json), if any.
std::optional<RenderProgress> progress_from_row(const PgRows& rows, int row);
std::string progress_to_json(const RenderProgress& p);

}  // namespace penumbra::server
