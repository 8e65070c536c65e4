#include "api/scene_loader.h"

#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>

#include "api/diagnostics.h"
#include "api/gltf_scene.h"
#include "renderer/io/file_bytes.h"
#include "renderer/io/gltf_file.h"
#include "api/json_document.h"
#include "api/render_overrides.h"
#include "api/scene_parser.h"

namespace penumbra::api {

std::string describe_image(int width, int height, int channels, const std::string& storage) {
  return std::to_string(width) + " x " + std::to_string(height) + ", " + std::to_string(channels) +
         (channels == 1 ? " channel, " : " channels, ") + storage;
}

LoadResult load_scene(std::string_view json_text, const Limits& limits,
                      std::span<const RenderOverride> overrides, const AssetFolder& assets) {
  LoadResult result;
  Diagnostics diag;
  try {
    JsonDocument document = parse_json_document(json_text, limits.max_json_depth, diag);
    if (document.syntax_error) {
      result.kind = LoadErrorKind::kSyntax;
    } else {
      // Duplicate keys were reported by the document parser; keep checking everything else.
      const std::optional<int> threads = apply_render_overrides(*document.value, overrides, diag);
      auto request = parse_scene(*document.value, limits, assets, diag);
      if (request && threads) request->settings.threads = *threads;
      if (!diag.has_errors()) result.request = std::move(request);
    }
  } catch (const std::bad_alloc&) {
    diag.error("", "the scene is too large to load (out of memory)");
  } catch (const std::exception& e) {
    // Reaching this is a bug in api/, but a caller (the HTTP service) must still get an answer.
    diag.error("", std::string("internal error while loading the scene: ") + e.what());
  }
  if (diag.has_errors() && result.kind == LoadErrorKind::kNone) result.kind = LoadErrorKind::kInvalid;
  if (!diag.has_errors() && !result.request) {  // cannot happen; never report success without one
    diag.error("", "internal error: no scene was produced");
    result.kind = LoadErrorKind::kInvalid;
  }
  result.errors = diag.take_errors();
  result.warnings = diag.take_warnings();
  return result;
}

LoadResult load_scene_file(const std::string& path, const Limits& limits,
                           std::span<const RenderOverride> overrides) {
  // A glTF asset renders as the scene gltf_scene.h builds around it.
  if (is_gltf_file_name(path)) return load_gltf_scene_file(path, limits, overrides);
  // Mapped, not copied (renderer/io/file_bytes.h): a scene with meshes inline is megabytes of
  // JSON, and a copy through a stream cost a fresh page per 4 KB, several times over as it grew.
  const auto cannot_read = [&path](const std::string& why) {
    LoadResult result;
    result.kind = LoadErrorKind::kInvalid;
    result.errors.push_back(
        {"", "cannot read file '" + path + "'" + (why.empty() ? "" : ": " + why)});
    return result;
  };
  FileBytes file;
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) {
    try {
      file = FileBytes::map(path, std::numeric_limits<int64_t>::max());
    } catch (const FileBytesError&) {
      return cannot_read("");
    }
  } else if (!std::filesystem::is_directory(path, ec)) {
    // A pipe (`penumbra render <(make_scene) ...`) or device: read through as a stream.
    std::ifstream stream(path, std::ios::binary);
    std::ostringstream text;
    if (stream.is_open()) text << stream.rdbuf();
    if (!stream.is_open() || stream.bad()) return cannot_read("");
    file = FileBytes(std::move(text).str());
  } else {
    return cannot_read("");
  }
  AssetFolder assets;
  assets.root = std::filesystem::absolute(std::filesystem::path(path)).parent_path();
  LoadResult result = load_scene(file.view(), limits, overrides, assets);
  if (!file.intact())
    return cannot_read("the file changed while it was read (or a part of it could not be read)");
  return result;
}

}  // namespace penumbra::api
