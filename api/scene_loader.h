#pragma once
// JSON scene (format v1) -> validated renderer input. The single entry point used by the CLI,
// the HTTP service and the tests. Every problem is reported with the JSON pointer of the field.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "api/animation.h"
#include "api/asset_path.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::api {

struct Diagnostic {
  std::string pointer;  // RFC 6901 JSON pointer, "" for the document root
  std::string message;
  // The command-line flag that supplied the value ("--width"), when one did: the CLI's user
  // typed no JSON there, so the message must name what they did type.
  std::string flag = {};
  // "/render/width: must be ...", or with a flag "--width (/render/width): must be ...".
  std::string to_string() const;
};

// Caps on what one scene may ask for; each documented in docs/scene-format.md.
struct Limits {
  int max_width = 8192;
  int max_height = 8192;
  int64_t max_pixels = int64_t(4096) * 4096;
  int max_spp = 1 << 20;
  int max_depth = 1024;
  int64_t max_triangles = 4'000'000;
  int64_t max_vertices = 12'000'000;              // mesh vertices, whole scene
  int64_t max_mesh_file_bytes = int64_t(1) << 30;  // any one mesh file
  int max_objects = 100'000;
  int64_t max_instances = 100'000;  // copies placed by "instances" objects, whole scene
  int max_materials = 10'000;
  int max_lights = 10'000;
  int max_json_depth = 64;
  double max_time_limit = 24 * 3600.0;  // seconds
  // Animations (docs/animation-and-windows.md): frames in one scene's range, and how far from 0
  // a frame number may lie (frame / fps stays exact enough in the camera's float times).
  int64_t max_frames = 100'000;
  int64_t max_frame_number = 1'000'000;
  // Textures (docs/scene-format.md): width x height of any one image, read from its header
  // before a pixel is decoded; and the decoded size of all of a scene's distinct images (each
  // file once per colorspace, at most 4 channels of 1 byte for 8-bit images, else 4-byte
  // floats: an 8192^2 RGBA PNG takes 256 MiB, the same as float EXR 1 GiB).
  int64_t max_texture_pixels = int64_t(8192) * 8192;
  int64_t max_texture_bytes = int64_t(1) << 30;
};

enum class LoadErrorKind {
  kNone,
  kSyntax,   // not JSON at all (or nested deeper than max_json_depth): HTTP 400
  kInvalid,  // JSON, but not a valid scene: HTTP 422
};

// A file the scene reads, for reports such as `penumbra info`.
struct AssetUse {
  std::string pointer;  // the field naming it, "/objects/3/file"
  std::string path;     // as the scene writes it
  std::string summary;  // what was read from it: "12000 triangles (6000 faces), normals, uvs"
};

// An image asset's AssetUse summary: "512 x 256, 3 channels, float"; `storage` is how the file
// stores its values ("float", "8-bit", "integer").
std::string describe_image(int width, int height, int channels, const std::string& storage);

struct SceneRequest {
  SceneInput scene;
  RenderSettings settings;
  // Positions in `scene` are relative to this point of the JSON's coordinate system (the camera
  // position): single-precision rendering keeps its accuracy however far from the JSON origin
  // the scene lies. Add it back to recover JSON coordinates.
  glm::dvec3 world_origin{0.0};
  // The environment map, the image textures (in the order materials and objects name them),
  // then the mesh and glTF files (in the order of the objects).
  std::vector<AssetUse> assets;
  int64_t texture_bytes = 0;  // the image textures' decoded size (api/texture_parser.h)
  // The scene's "animation" (api/animation.h). With one, `scene` is set to its first frame;
  // select_frame chooses another.
  std::optional<Animation> animation;
};

struct LoadResult {
  std::optional<SceneRequest> request;  // set iff errors is empty
  LoadErrorKind kind = LoadErrorKind::kNone;
  std::vector<Diagnostic> errors;
  std::vector<Diagnostic> warnings;
  bool ok() const { return errors.empty(); }
};

// A command-line flag overriding a member of the scene's "render" block, as typed ("--width",
// "640"); api/render_overrides.h lists the flags and says how they are checked.
struct RenderOverride {
  std::string flag;
  std::string value;
};

// `overrides` (the CLI's render flags; none for the service) are written into the document
// before it is checked, so they meet the same checks and limits as the JSON they replace.
// `assets` is the folder files named in the scene are read from (empty: the scene may name none).
LoadResult load_scene(std::string_view json_text, const Limits& limits = {},
                      std::span<const RenderOverride> overrides = {},
                      const AssetFolder& assets = {});
// Reads the file (a read failure is reported as an error on pointer "") and calls load_scene
// with the file's folder as the asset folder. A glTF file (.gltf, .glb) is loaded as the scene
// api/gltf_scene.h builds around it.
LoadResult load_scene_file(const std::string& path, const Limits& limits = {},
                           std::span<const RenderOverride> overrides = {});

}  // namespace penumbra::api
