#include "server/http/submission_problem.h"

#include "server/http/job_json.h"
#include "server/http/json_response.h"

namespace penumbra::server {

std::optional<Problem> submission_problem(const SubmitOutcome& o) {
  using K = SubmitOutcome::Kind;
  switch (o.kind) {
    case K::kAccepted:
    case K::kReplayed:
      return std::nullopt;
    case K::kSyntax: {
      Problem p =
          make_problem(400, "malformed-json", "Malformed JSON",
                       o.errors.empty() ? "the body is not JSON" : o.errors.front().message);
      p.extensions["errors"] = diagnostics_json(o.errors);
      return p;
    }
    case K::kInvalid: {
      Problem p =
          make_problem(422, "invalid-scene", "Invalid scene",
                       std::to_string(o.errors.size()) + " error(s) in the scene; see errors");
      p.extensions["errors"] = diagnostics_json(o.errors);
      if (!o.warnings.empty()) p.extensions["warnings"] = diagnostics_json(o.warnings);
      return p;
    }
    case K::kKeyReused: {
      Problem p = make_problem(
          422, "idempotency-key-reused", "Idempotency-Key reused",
          "this Idempotency-Key was used for a different scene (job " + o.record.id + ")");
      p.extensions["job"] = job_path(o.record.id);
      return p;
    }
    case K::kQueueFull: {
      Problem p = make_problem(429, "queue-full", "Queue full",
                               "the render queue is full (--max-queue); retry later");
      p.retry_after_seconds = o.retry_after_seconds;
      return p;
    }
    case K::kNotAccepting: {
      Problem p = make_problem(503, "shutting-down", "Shutting down",
                               "the server is shutting down and takes no new jobs");
      p.retry_after_seconds = o.retry_after_seconds;
      return p;
    }
    case K::kStoreFailed: {
      Problem p = make_problem(503, "storage-error", "Storage error",
                               "the job could not be stored; nothing was accepted, retry");
      p.retry_after_seconds = o.retry_after_seconds;
      return p;
    }
    case K::kNoSpace: {
      Problem p = make_problem(
          507, "insufficient-storage", "Insufficient Storage",
          "the data directory has " + std::to_string(o.bytes_available) +
              " bytes available; this job needs up to " + std::to_string(o.bytes_needed) +
              " (its images at worst, the images of jobs already accepted, and --min-free-space)");
      p.extensions["bytes_available"] = o.bytes_available;
      p.extensions["bytes_needed"] = o.bytes_needed;
      p.retry_after_seconds = 60;
      return p;
    }
  }
  return status_problem(500, "");
}

}  // namespace penumbra::server
