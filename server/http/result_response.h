#pragma once
// Streams a stored result image as the answer (GET /v1/jobs/{id}/result, POST /v1/render).
#include <string>

#include "renderer/io/image_io.h"
#include "server/jobs/job_service.h"

namespace httplib {
struct Response;
}

namespace penumbra::server {

// False when the job has no stored result in that format. The stream stays open, so a
// concurrent DELETE of the job does not cut the answer short. The status is left unset: the
// library answers 206 for a (single) Range request, else 200.
bool send_result(httplib::Response& res, const JobService& jobs, const std::string& id,
                 ImageFormat format);

}  // namespace penumbra::server
