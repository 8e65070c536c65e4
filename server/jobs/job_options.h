#pragma once
// What a submission says about the job rather than the picture: "priority" and "notify" at the
// top level of the POST /v1/jobs body. They are taken out before the rest is read as the scene
// (the scene format knows nothing of queues or webhooks; the CLI renders the same scene), so a
// body is a scene plus, optionally, these members:
//   {"priority": 10, "notify": {"url": "https://ci.example/hook", "secret": "..."}, ...scene}
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/scene_loader.h"
#include "server/jobs/webhook_url.h"

namespace penumbra::server {

// Priority bounds (documented in docs/http-api.md): a small range, so "more important" stays a
// decision and not an arms race of ever larger numbers.
constexpr int kMinPriority = -1000;
constexpr int kMaxPriority = 1000;
// Secret length bounds for webhook signatures, in bytes.
constexpr std::size_t kMinSecretBytes = 16;
constexpr std::size_t kMaxSecretBytes = 1024;

struct JobOptions {
  int priority = 0;
  std::string notify_url;  // "" = no webhook
  std::string notify_secret;
};

struct SplitSubmission {
  // The scene text to load: the body itself when it has none of the members, else the body
  // without them.
  std::string scene_text;
  JobOptions options;
  std::vector<api::Diagnostic> errors;  // on /priority, /notify/...
};

// `allowed` is --webhook-allow-hosts (empty: webhooks off). A body that is not a JSON object
// comes back unchanged, for the scene loader to report.
SplitSubmission split_job_options(std::string_view body, const std::vector<AllowedHost>& allowed,
                                  int max_json_depth);

}  // namespace penumbra::server
