#include "server/http/one_shot_job.h"

#include <httplib.h>

#include <algorithm>
#include <cstdlib>

#include "api/diagnostics.h"
#include "api/gltf_scene.h"
#include "api/job_submission.h"
#include "api/json_document.h"
#include "api/render_overrides.h"
#include "server/http/json_response.h"
#include "server/jobs/submission_check.h"
#include "server/http/multipart.h"
#include "server/text_util.h"

namespace penumbra::server {
namespace {

using Json = api::Json;

// The media type alone, lower case.
std::string media_type(const std::string& content_type) {
  std::string type = ascii_lower(content_type);
  return std::string(trim_ows(type.substr(0, type.find(';'))));
}

Problem invalid(const std::vector<api::Diagnostic>& errors, const std::string& what) {
  Problem p = make_problem(422, "invalid-scene", "Invalid scene",
                           std::to_string(errors.size()) + " error(s) in the " + what +
                               "; see errors");
  p.extensions["errors"] = diagnostics_json(errors);
  return p;
}

Problem store_problem(PutStatus status, const AssetStore& store, const std::string& name) {
  if (status == PutStatus::kNoRoom) {
    Problem p = make_problem(507, "asset-store-full", "Insufficient Storage",
                             "the asset store (--max-asset-store " +
                                 std::to_string(store.limits().max_store_bytes) +
                                 " bytes) has no room for " + api::quote_user_string(name) +
                                 " beside the assets queued or running jobs use; retry later");
    p.retry_after_seconds = 30;
    return p;
  }
  Problem p = make_problem(413, "asset-too-large", "Content Too Large",
                           api::quote_user_string(name) + " is larger than " +
                               std::to_string(store.limits().max_asset_bytes) +
                               " bytes (--max-asset-size)");
  return p;
}

std::variant<std::string, Problem> multipart_job(const RouteContext& c,
                                                 const httplib::Request& req,
                                                 const std::string& content_type) {
  AssetStore& store = *c.jobs.assets();
  const auto boundary = multipart_boundary(content_type);
  if (!boundary)
    return make_problem(400, "malformed-form", "Malformed form",
                        "multipart/form-data needs a boundary parameter of 1 to 70 characters");
  MultipartLimits limits;
  limits.max_parts = std::size_t(c.config.max_job_files) + 1;
  const MultipartResult form = parse_multipart(req.body, *boundary, limits);
  if (!form.error.empty())
    return make_problem(400, "malformed-form", "Malformed form", form.error);
  const api::ManifestLimits manifest_limits_ = manifest_limits(c.config);
  std::vector<api::Diagnostic> errors;
  const MultipartPart* scene = nullptr;
  std::vector<const MultipartPart*> files;
  for (const MultipartPart& part : form.parts) {
    if (part.name == "scene") {
      if (scene) errors.push_back({"/scene", "the form has two parts named 'scene'"});
      scene = &part;
      continue;
    }
    const std::string pointer = api::child_pointer("/assets", part.name);
    if (auto problem = api::manifest_name_problem(part.name, manifest_limits_)) {
      errors.push_back({pointer, *problem + " (" + api::quote_user_string(part.name) + ")"});
      continue;
    }
    for (const MultipartPart* f : files)
      if (f->name == part.name) errors.push_back({pointer, "the form has two parts of this name"});
    files.push_back(&part);
  }
  if (!scene)
    errors.push_back({"/scene", "the form has no part named 'scene' (curl -F scene=@scene.json)"});
  if (!errors.empty()) return invalid(errors, "form");
  api::Diagnostics diag;
  const api::JsonDocument doc =
      api::parse_json_document(scene->data, c.config.scene_limits().max_json_depth, diag);
  if (doc.syntax_error || diag.has_errors()) {
    auto errs = diag.take_errors();
    api::rebase_scene_diagnostics(errs);
    if (!doc.syntax_error) return invalid(errs, "scene part");
    Problem p = make_problem(400, "malformed-json", "Malformed JSON",
                             "the part 'scene' is not JSON: " +
                                 (errs.empty() ? std::string() : errs.front().message));
    p.extensions["errors"] = diagnostics_json(errs);
    return p;
  }
  Json manifest = Json::object();
  for (const MultipartPart* f : files) {
    std::string hash;
    const PutResult r = store.put_bytes(f->data, &hash);
    if (r.status != PutStatus::kStored && r.status != PutStatus::kAlreadyStored)
      return store_problem(r.status, store, f->name);
    manifest[f->name] = "sha256:" + hash;
  }
  return Json{{"scene", *doc.value}, {"assets", manifest}}.dump();
}

std::variant<std::string, Problem> gltf_binary_job(const RouteContext& c,
                                                   const httplib::Request& req) {
  AssetStore& store = *c.jobs.assets();
  constexpr const char* kName = "model.glb";
  // Query parameters: the render block's members (width, height, spp, max_depth, seed ...).
  Json render = Json::object();
  Json job = Json::object();
  for (const auto& [key, value] : req.params) {
    if (key == "priority") {  // the job's own, not the render block's (job_options.h checks it)
      char* end = nullptr;
      const long long p = std::strtoll(value.c_str(), &end, 10);
      if (value.empty() || !end || *end != '\0' || p < -1000000 || p > 1000000)
        return invalid_parameter(key, "must be an integer (the job's run order, higher first)");
      job["priority"] = p;
      continue;
    }
    std::string flag = "--" + key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    if (!api::is_render_override_flag(flag) || flag == api::kThreadsFlag)
      return invalid_parameter(key, "is not a member of the scene's render block (width, "
                                    "height, spp, max_depth, seed, ...)");
    render[key] = api::override_value({flag, value});
  }
  std::string hash;
  const PutResult r = store.put_bytes(req.body, &hash);
  if (r.status != PutStatus::kStored && r.status != PutStatus::kAlreadyStored)
    return store_problem(r.status, store, kName);
  const std::string staged = store.stage(hash, kName);
  api::LoadResult result;
  std::string document;
  try {
    document = api::gltf_scene_document(staged, c.config.scene_limits(), &result);
  } catch (...) {
    store.unstage(staged);
    throw;
  }
  store.unstage(staged);
  if (document.empty()) {
    for (api::Diagnostic& d : result.errors)
      if (d.pointer.empty()) d.pointer = api::child_pointer("/assets", kName);
    return invalid(result.errors, "glTF file");
  }
  Json scene = Json::parse(document);
  for (const auto& [key, value] : render.items()) scene["render"][key] = value;
  job["scene"] = scene;
  job["assets"] = {{kName, "sha256:" + hash}};
  return job.dump();
}

}  // namespace

bool is_one_shot_job(const httplib::Request& req) { return req.has_header(kOneShotTypeHeader); }

std::variant<std::string, Problem> one_shot_job_body(const RouteContext& c,
                                                     const httplib::Request& req) {
  if (!c.jobs.assets()) return status_problem(415, "this server keeps no assets");
  const std::string content_type = req.get_header_value(kOneShotTypeHeader);
  const std::string type = media_type(content_type);
  if (type == "multipart/form-data") return multipart_job(c, req, content_type);
  return gltf_binary_job(c, req);
}

}  // namespace penumbra::server
