// libFuzzer target for what a job submission's body goes through before the scene loader: the
// multipart/form-data parser of the one-shot form (server/http/multipart.h), the Content-Type
// boundary parameter, and the job envelope with its manifest names (api/job_submission.h).
// Input: the first line is the Content-Type, the rest the body. Invariants: every part's data is
// a view inside the body, the part count respects the cap, and an accepted manifest name cannot
// leave a folder (no "..", no absolute path, no backslash or NUL).
#include <cstdint>
#include <string_view>

#include "api/job_submission.h"
#include "server/http/multipart.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  const auto nl = in.find('\n');
  const std::string_view type = in.substr(0, nl);
  const std::string_view body = nl == std::string_view::npos ? std::string_view() : in.substr(nl + 1);
  server::MultipartLimits limits;
  limits.max_parts = 8;
  const std::string boundary = server::multipart_boundary(type).value_or("XYZ");
  const server::MultipartResult form = server::parse_multipart(body, boundary, limits);
  if (form.parts.size() > limits.max_parts) __builtin_trap();
  const api::ManifestLimits manifest;
  for (const server::MultipartPart& p : form.parts) {
    if (p.data.data() < body.data() || p.data.data() + p.data.size() > body.data() + body.size())
      __builtin_trap();
    if (!api::manifest_name_problem(p.name, manifest)) {
      const std::string_view n = p.name;
      if (n.empty() || n.front() == '/' || n.find('\\') != n.npos || n.find('\0') != n.npos ||
          n == ".." || n.rfind("../", 0) == 0 || n.find("/../") != n.npos ||
          (n.size() >= 3 && n.substr(n.size() - 3) == "/.."))
        __builtin_trap();
    }
  }
  const api::JobSubmission job = api::parse_job_submission(in, 64, manifest);
  for (const api::ManifestEntry& e : job.assets)
    if (api::manifest_name_problem(e.name, manifest) || !api::is_sha256_hex(e.hash)) __builtin_trap();
  return 0;
}
