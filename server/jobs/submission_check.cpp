#include "server/jobs/submission_check.h"

#include <algorithm>
#include <cstdio>
#include <random>

#include "api/diagnostics.h"
#include "api/job_submission.h"
#include "api/scene_loader.h"
#include "server/jobs/job_options.h"
#include "server/jobs/unix_time.h"
#include "server/storage/disk_space.h"

namespace penumbra::server {
namespace {

nlohmann::json diagnostics_json(const std::vector<api::Diagnostic>& ds) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& d : ds) a.push_back({{"pointer", d.pointer}, {"detail", d.message}});
  return a;
}

// Links the manifest's files into the job's folder; a refusal (missing hashes: 422, over
// --max-job-assets: 422, storage failure: 503) or nullopt.
std::optional<SubmitOutcome> link_assets(const ServerConfig& config, AssetStore& assets,
                                         const std::string& job_id,
                                         const std::vector<api::ManifestEntry>& manifest) {
  SubmitOutcome out;
  out.kind = SubmitOutcome::Kind::kInvalid;
  std::uint64_t total = 0;
  for (const api::ManifestEntry& m : manifest) total += assets.size_of(m.hash).value_or(0);
  if (total > config.max_job_asset_bytes) {
    out.errors.push_back({"/assets", "the files add up to " + std::to_string(total) +
                                         " bytes; the limit is " +
                                         std::to_string(config.max_job_asset_bytes) +
                                         " (--max-job-assets)"});
    return out;
  }
  JobLinkResult linked;
  try {
    linked = assets.link_job_folder(job_id, manifest);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "penumbra serve: linking the assets of a new job failed: %s\n", e.what());
    out.kind = SubmitOutcome::Kind::kStoreFailed;
    out.retry_after_seconds = 5;
    return out;
  }
  if (linked.ok()) return std::nullopt;
  for (const std::string& name : linked.missing) {
    const auto it = std::find_if(manifest.begin(), manifest.end(),
                                 [&](const api::ManifestEntry& m) { return m.name == name; });
    out.errors.push_back({api::child_pointer("/assets", name),
                          "no asset sha256:" + it->hash +
                              " is stored; upload it first with PUT /v1/assets/" + it->hash +
                              " (POST /v1/assets/missing lists what to upload)"});
  }
  return out;
}

}  // namespace

api::ManifestLimits manifest_limits(const ServerConfig& config) {
  api::ManifestLimits m;
  m.max_files = config.max_job_files;
  return m;
}

std::string new_job_id() {
  static thread_local std::random_device rd;  // /dev/urandom: ids are unguessable
  static const char* kHex = "0123456789abcdef";
  std::string id;
  for (int i = 0; i < 6; ++i) {
    const uint32_t v = rd();
    for (int k = 0; k < 4; ++k) id += kHex[(v >> (k * 4)) & 15];
  }
  return id;
}

JobFolderGuard::~JobFolderGuard() {
  if (assets_) assets_->remove_job_folder(id_);
}

void JobFolderGuard::commit() {
  if (assets_) assets_->commit_job_folder(id_);
  assets_ = nullptr;
}

PreparedSubmission prepare_submission(const ServerConfig& config, AssetStore* assets,
                                      std::string_view body, const std::string& idempotency_key) {
  PreparedSubmission prepared;
  SubmitOutcome out;
  const api::Limits limits = config.scene_limits();
  // "priority" and "notify" are the job's, not the scene's (job_options.h): taken off the top
  // level of a bare scene or of an envelope first.
  SplitSubmission split = split_job_options(body, config.webhook_hosts(), limits.max_json_depth);
  // A bare scene, or {"scene": ..., "assets": {name: "sha256:..."}} (api/job_submission.h).
  api::JobSubmission submission = api::parse_job_submission(
      split.scene_text, limits.max_json_depth, manifest_limits(config));
  if (!submission.ok()) {
    out.kind = submission.kind == api::LoadErrorKind::kSyntax ? SubmitOutcome::Kind::kSyntax
                                                              : SubmitOutcome::Kind::kInvalid;
    out.errors = std::move(split.errors);
    out.errors.insert(out.errors.end(), submission.errors.begin(), submission.errors.end());
    prepared.refusal = std::move(out);
    return prepared;
  }
  const std::string job_id = new_job_id();
  api::AssetFolder folder;
  folder.max_file_bytes = int64_t(config.max_asset_bytes);
  folder.missing_hint = "; name it in the job's \"assets\" manifest ({\"scene\": ..., "
                        "\"assets\": {\"NAME\": \"sha256:...\"}}) after uploading it with PUT "
                        "/v1/assets/{sha256}";
  if (!submission.assets.empty()) {
    if (!assets) {
      out.kind = SubmitOutcome::Kind::kInvalid;
      out.errors.push_back({"/assets", "this server keeps no assets"});
      prepared.refusal = std::move(out);
      return prepared;
    }
    if (std::optional<SubmitOutcome> refused =
            link_assets(config, *assets, job_id, submission.assets)) {
      prepared.refusal = std::move(*refused);
      return prepared;
    }
    // The job's folder of hard links (asset_store.h) exists from here; it is removed on every
    // way out but acceptance.
    prepared.folder = std::make_unique<JobFolderGuard>(assets, job_id);
    folder.root = assets->job_folder(job_id);
  }
  api::LoadResult loaded = api::load_scene(submission.scene_text, limits, {}, folder);
  if (submission.enveloped) {
    api::rebase_scene_diagnostics(loaded.errors);
    api::rebase_scene_diagnostics(loaded.warnings);
  }
  prepared.warnings = loaded.warnings;
  if (!loaded.ok() || !split.errors.empty()) {
    out.kind = loaded.kind == api::LoadErrorKind::kSyntax ? SubmitOutcome::Kind::kSyntax
                                                          : SubmitOutcome::Kind::kInvalid;
    out.errors = std::move(split.errors);
    out.errors.insert(out.errors.end(), loaded.errors.begin(), loaded.errors.end());
    out.warnings = loaded.warnings;
    prepared.refusal = std::move(out);
    return prepared;
  }
  const JobOptions& options = split.options;
  const RenderSettings& s = loaded.request->settings;
  JobRecord& r = prepared.record;
  r.id = job_id;
  r.idempotency_key = idempotency_key;
  r.created_at = unix_now();
  r.width = s.width;
  r.height = s.height;
  r.spp = s.spp;
  r.samples_total = uint64_t(s.width) * uint64_t(s.height) * uint64_t(s.spp);
  if (const auto& animation = loaded.request->animation) {
    // Every frame is rendered (and kept): the totals count them all.
    r.frame_first = int(animation->first_frame);
    r.frame_last = int(animation->last_frame);
    r.samples_total *= uint64_t(r.frame_count());
  }
  r.priority = options.priority;
  r.notify.url = options.notify_url;
  r.notify.secret = options.notify_secret;
  if (!prepared.warnings.empty()) r.warnings_json = diagnostics_json(prepared.warnings).dump();
  prepared.worst_case_bytes = worst_case_result_bytes(s.width, s.height, s.outputs) *
                              uint64_t(std::max(1, r.frame_count()));
  // What the worker renders: the scene (or envelope) without the job's options.
  prepared.scene_json = std::move(split.scene_text);
  return prepared;
}

}  // namespace penumbra::server
