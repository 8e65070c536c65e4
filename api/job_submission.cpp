#include "api/job_submission.h"

#include <algorithm>

#include "api/diagnostics.h"
#include "api/json_document.h"

namespace penumbra::api {

bool is_sha256_hex(std::string_view text) {
  if (text.size() != 64) return false;
  return std::all_of(text.begin(), text.end(),
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

std::optional<std::string> parse_hash_reference(std::string_view text) {
  constexpr std::string_view kPrefix = "sha256:";
  if (text.substr(0, kPrefix.size()) != kPrefix) return std::nullopt;
  const std::string_view hex = text.substr(kPrefix.size());
  if (!is_sha256_hex(hex)) return std::nullopt;
  return std::string(hex);
}

std::optional<std::string> manifest_name_problem(std::string_view name,
                                                 const ManifestLimits& limits) {
  if (name.empty()) return "a file name must not be empty";
  if (name.size() > limits.max_name_bytes)
    return "a file name must be at most " + std::to_string(limits.max_name_bytes) + " bytes";
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u == 0) return "a file name must not contain a NUL character";
    if (u < 0x20 || u == 0x7f) return "a file name must not contain control characters";
    if (c == '\\') return "a file name must use '/' between folders, not '\\'";
  }
  if (name.front() == '/') return "a file name must be relative, not absolute";
  int depth = 0;
  std::size_t begin = 0;
  while (begin <= name.size()) {
    const std::size_t end = std::min(name.find('/', begin), name.size());
    const std::string_view part = name.substr(begin, end - begin);
    if (part.empty()) return "a file name must not have an empty folder name ('//' or a trailing '/')";
    if (part == "." || part == "..") return "a file name must not have a '.' or '..' component";
    if (part.size() > limits.max_component_bytes)
      return "each folder or file name must be at most " +
             std::to_string(limits.max_component_bytes) + " bytes";
    if (++depth > limits.max_depth)
      return "a file name must have at most " + std::to_string(limits.max_depth) + " components";
    begin = end + 1;
  }
  return std::nullopt;
}

namespace {

void parse_manifest(const Json& assets, const ManifestLimits& limits, Diagnostics& diag,
                    std::vector<ManifestEntry>& out) {
  if (!assets.is_object()) {
    diag.error("/assets", "must be an object mapping file names to \"sha256:<64 hex digits>\"");
    return;
  }
  if (assets.size() > std::size_t(limits.max_files)) {
    diag.error("/assets", "names " + std::to_string(assets.size()) + " files; the limit is " +
                              std::to_string(limits.max_files) + " (--max-job-files)");
    return;
  }
  for (const auto& [name, value] : assets.items()) {
    const std::string pointer = child_pointer("/assets", name);
    if (auto problem = manifest_name_problem(name, limits)) {
      diag.error(pointer, *problem + " (" + quote_user_string(name) + ")");
      continue;
    }
    const auto hash = value.is_string() ? parse_hash_reference(value.get<std::string>())
                                        : std::nullopt;
    if (!hash) {
      diag.error(pointer, "must be \"sha256:\" followed by 64 lowercase hex digits");
      continue;
    }
    out.push_back({name, *hash});
  }
  std::sort(out.begin(), out.end(),
            [](const ManifestEntry& a, const ManifestEntry& b) { return a.name < b.name; });
  // "a" and "a/b" cannot both exist in one folder: "a" would be a file and a folder.
  for (std::size_t i = 0; i + 1 < out.size(); ++i) {
    const std::string& a = out[i].name;
    for (std::size_t j = i + 1; j < out.size() && out[j].name.compare(0, a.size(), a) == 0; ++j)
      if (out[j].name.size() > a.size() && out[j].name[a.size()] == '/')
        diag.error(child_pointer("/assets", out[j].name),
                   quote_user_string(a) + " is a file, so it cannot also be a folder");
  }
}

}  // namespace

JobSubmission parse_job_submission(std::string_view body, int max_json_depth,
                                   const ManifestLimits& limits) {
  JobSubmission out;
  Diagnostics diag;
  JsonDocument doc = parse_json_document(body, max_json_depth, diag);
  if (doc.syntax_error) {
    out.kind = LoadErrorKind::kSyntax;
    out.errors = diag.take_errors();
    return out;
  }
  const Json& root = *doc.value;
  if (!root.is_object() || !root.contains("scene")) {
    // A bare scene: load_scene reads the text as it came (and reports any duplicate key again).
    out.scene_text = std::string(body);
    return out;
  }
  out.enveloped = true;
  for (const auto& [key, value] : root.items())
    if (key != "scene" && key != "assets")
      diag.error(child_pointer("", key),
                 "unknown member of a job" + did_you_mean(key, {"scene", "assets"}) +
                     "; a job is {\"scene\": {...}, \"assets\": {...}}");
  if (!root["scene"].is_object()) diag.error("/scene", "must be a scene object");
  if (root.contains("assets")) parse_manifest(root["assets"], limits, diag, out.assets);
  if (diag.has_errors()) {
    out.kind = LoadErrorKind::kInvalid;
    out.errors = diag.take_errors();
    return out;
  }
  out.scene_text = root["scene"].dump();
  return out;
}

void rebase_scene_diagnostics(std::vector<Diagnostic>& diagnostics) {
  for (Diagnostic& d : diagnostics) d.pointer = "/scene" + d.pointer;
}

}  // namespace penumbra::api
