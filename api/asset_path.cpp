#include "api/asset_path.h"

#include <algorithm>

#include "api/diagnostics.h"

namespace penumbra::api {

namespace fs = std::filesystem;

std::optional<fs::path> resolve_asset_path(const AssetFolder& folder, const std::string& relative,
                                           const std::string& pointer, Diagnostics& diag) {
  if (folder.root.empty()) {
    diag.error(pointer, "this scene cannot name files: it has no asset folder" + folder.missing_hint);
    return std::nullopt;
  }
  if (relative.empty()) {
    diag.error(pointer, "must be a file name, not empty");
    return std::nullopt;
  }
  if (relative.find('\0') != std::string::npos) {
    diag.error(pointer, "must not contain a NUL character");
    return std::nullopt;
  }
  const fs::path rel(relative);
  if (rel.is_absolute() || rel.has_root_name() || rel.has_root_directory()) {
    diag.error(pointer, "must be relative to the scene's folder, not absolute ('" + relative + "')");
    return std::nullopt;
  }
  for (const fs::path& part : rel)
    if (part == "..") {
      diag.error(pointer, "must stay inside the scene's folder: '..' is not allowed ('" + relative + "')");
      return std::nullopt;
    }
  std::error_code ec;
  const fs::path root = fs::canonical(folder.root, ec);
  if (ec) {
    diag.error(pointer, "the asset folder cannot be read: " + ec.message());
    return std::nullopt;
  }
  const fs::path full = fs::canonical(root / rel, ec);
  if (ec) {
    diag.error(pointer, "no such file in the scene's folder: '" + relative + "'" + folder.missing_hint);
    return std::nullopt;
  }
  // Symbolic links are followed; the target must still be inside the folder.
  const auto [root_end, full_it] = std::mismatch(root.begin(), root.end(), full.begin(), full.end());
  if (root_end != root.end()) {
    diag.error(pointer, "must stay inside the scene's folder: '" + relative + "' leads outside it");
    return std::nullopt;
  }
  if (!fs::is_regular_file(full, ec)) {
    diag.error(pointer, "must name a regular file: '" + relative + "'");
    return std::nullopt;
  }
  const auto size = fs::file_size(full, ec);
  if (ec || int64_t(size) > folder.max_file_bytes) {
    diag.error(pointer, "'" + relative + "' is larger than the limit of " +
                            std::to_string(folder.max_file_bytes) + " bytes");
    return std::nullopt;
  }
  return full;
}

}  // namespace penumbra::api
