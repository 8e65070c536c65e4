#pragma once
// Asset files a scene names (mesh files, textures, environment maps) are read only from one
// folder: the scene file's folder for the CLI, the job's asset folder for the service. A path
// in a scene is relative to it; absolute paths, paths with a `..` component, and paths that
// leave the folder through a symbolic link are errors naming the field.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace penumbra::api {

class Diagnostics;

struct AssetFolder {
  std::filesystem::path root;  // empty: this scene may not name files (e.g. inline JSON only)
  int64_t max_file_bytes = int64_t(2) << 30;  // any one asset file
  // Appended to the error for a file that is not there, to say where it should come from (the
  // service: the job's "assets" manifest).
  std::string missing_hint = {};
};

// The canonical path of an existing regular file inside the folder, or nullopt with an error
// on `pointer` (the field that holds the path).
std::optional<std::filesystem::path> resolve_asset_path(const AssetFolder& folder,
                                                        const std::string& relative,
                                                        const std::string& pointer,
                                                        Diagnostics& diag);

}  // namespace penumbra::api
