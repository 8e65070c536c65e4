#pragma once
// The body of POST /v1/jobs: either a bare scene (as before assets existed) or an envelope
//   {"scene": {...}, "assets": {"bunny.ply": "sha256:<64 hex>", "textures/wood.png": "..."}}
// whose manifest names every file the scene reads. The names are the paths the scene uses; the
// service links each named file from its content-addressed store into a folder of the job's own
// (server/storage/asset_store.h), which is the only folder the scene loader may read.
//
// Manifest names are checked here, before anything touches a file system: they must be plain
// relative paths that cannot leave that folder however they are read (no absolute path, no
// "." or ".." component, no empty component, no backslash, no control character), bounded in
// length and depth. A name such as "%2e%2e/x" is a literal file name: nothing decodes it.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/scene_loader.h"

namespace penumbra::api {

// Caps on a job's manifest (the serve flags --max-job-files; the rest are fixed).
struct ManifestLimits {
  int max_files = 1000;
  std::size_t max_name_bytes = 1024;   // the whole path
  std::size_t max_component_bytes = 255;  // one file or folder name (NAME_MAX on Linux)
  int max_depth = 16;                  // components in one path
};

struct ManifestEntry {
  std::string name;  // the path the scene uses
  std::string hash;  // 64 lowercase hex digits (the "sha256:" prefix removed)
};

struct JobSubmission {
  bool enveloped = false;    // {"scene": ..., "assets": ...} rather than a bare scene
  std::string scene_text;    // the scene's JSON text, to hand to load_scene
  std::vector<ManifestEntry> assets;  // sorted by name
  LoadErrorKind kind = LoadErrorKind::kNone;
  std::vector<Diagnostic> errors;
  bool ok() const { return errors.empty(); }
};

// Splits the body; errors name the JSON pointer of the field ("/assets/bunny.ply",
// "/scene"). The scene itself is not checked here (load_scene does that).
JobSubmission parse_job_submission(std::string_view body, int max_json_depth,
                                   const ManifestLimits& limits);

// Why `name` cannot be a manifest name, or nullopt when it can.
std::optional<std::string> manifest_name_problem(std::string_view name,
                                                 const ManifestLimits& limits);

// "sha256:" + 64 lowercase hex digits -> the digits; nullopt otherwise.
std::optional<std::string> parse_hash_reference(std::string_view text);
// 64 lowercase hex digits.
bool is_sha256_hex(std::string_view text);

// The loader's diagnostics are about the scene alone; inside an envelope their pointers gain
// the "/scene" prefix so they name the field of the body the client sent.
void rebase_scene_diagnostics(std::vector<Diagnostic>& diagnostics);

}  // namespace penumbra::api
