#pragma once
// Streams a stored result image as the answer (GET /v1/jobs/{id}/result, POST /v1/render).
#include <optional>
#include <string>

#include "renderer/io/image_io.h"
#include "server/jobs/job_service.h"

namespace httplib {
struct Response;
}

namespace penumbra::server {

// False when the job has no stored result in that format. The stream stays open, so a
// concurrent DELETE of the job does not cut the answer short. `range` is the Range header:
// answered 206 with Content-Range, or 416 outside the file (byte_range.h); the library's own
// range handling is off (request_guard clears the parsed ranges).
// `variant` names which of the job's result files (server/storage/result_files.h): "" the
// beauty image, "blender" the Blender-layout EXR, or an output layer's name.
// `frame`: a frame of an animation job (nullopt: a still's image, or an animation's first frame);
// its file is named <id>.frame_0017.<key> in Content-Disposition.
bool send_result(httplib::Response& res, const JobBackend& jobs, const std::string& id,
                 ImageFormat format, const std::optional<std::string>& range,
                 const std::string& variant = "", std::optional<int> frame = std::nullopt);

}  // namespace penumbra::server
