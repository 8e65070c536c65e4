#include "api/gltf_scene.h"

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "api/diagnostics.h"
#include "api/gltf_parser.h"

namespace penumbra::api {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kWidth = 800;           // the render's width; the height follows the aspect
constexpr double kDefaultAspect = 4.0 / 3.0;
constexpr double kFramingFov = 40.0;  // degrees, vertical, for the framing camera

json vec(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }

// World-space bounds of every placed mesh (double precision).
bool asset_bounds(const GltfAsset& asset, glm::dvec3* lo, glm::dvec3* hi) {
  bool any = false;
  *lo = glm::dvec3(std::numeric_limits<double>::max());
  *hi = -*lo;
  for (const GltfMeshInstance& inst : asset.instances)
    for (const GltfPrimitive& prim : asset.meshes[size_t(inst.mesh)].primitives)
      for (const vec3& p : prim.positions) {
        const glm::dvec3 w = glm::dvec3(inst.to_world * glm::dvec4(glm::dvec3(p), 1.0));
        *lo = glm::min(*lo, w);
        *hi = glm::max(*hi, w);
        any = true;
      }
  return any;
}

}  // namespace

std::string gltf_scene_document(const std::string& path, const Limits& limits, LoadResult* result) {
  AssetFolder assets;
  assets.root = fs::absolute(fs::path(path)).parent_path();
  assets.max_file_bytes = std::max<int64_t>(assets.max_file_bytes, limits.max_mesh_file_bytes);
  const std::string file = fs::path(path).filename().string();
  Diagnostics diag;
  const auto asset = read_gltf_asset(file, "", limits, assets, diag);
  if (!asset) {
    result->kind = LoadErrorKind::kInvalid;
    result->errors = diag.take_errors();
    result->warnings = diag.take_warnings();
    return {};
  }

  json camera;
  double aspect = kDefaultAspect;
  const GltfCamera* cam = nullptr;
  for (const GltfCamera& c : asset->cameras)
    if (c.perspective) {
      cam = &c;
      break;
    }
  if (cam) {
    // glTF cameras look down their -z with +y up (glTF 2.0 section 3.10).
    const glm::dvec3 position(cam->to_world[3]);
    const glm::dvec3 forward = glm::normalize(glm::dvec3(cam->to_world * glm::dvec4(0, 0, -1, 0)));
    const glm::dvec3 up = glm::normalize(glm::dvec3(cam->to_world * glm::dvec4(0, 1, 0, 0)));
    camera = {{"position", vec(position)}, {"look_at", vec(position + forward)}, {"up", vec(up)},
              {"fov", cam->yfov * 180.0 / kPi}};
    if (cam->aspect_ratio > 0) aspect = cam->aspect_ratio;
  } else {
    // Frame the bounding sphere from the front, a little from the right and above (glTF's
    // front is +z, up +y), with 10% to spare.
    glm::dvec3 lo, hi;
    if (!asset_bounds(*asset, &lo, &hi)) lo = hi = glm::dvec3(0.0);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * glm::length(hi - lo), 1e-3);
    const double half_fov = 0.5 * kFramingFov * kPi / 180.0;
    // The narrower (vertical) field must hold the sphere: distance = r / sin(half fov).
    const double distance = 1.1 * radius / std::sin(half_fov);
    const glm::dvec3 direction = glm::normalize(glm::dvec3(0.45, 0.35, 1.0));
    camera = {{"position", vec(centre + distance * direction)}, {"look_at", vec(centre)},
              {"up", json::array({0, 1, 0})}, {"fov", kFramingFov}};
  }
  const int height = std::max(1, int(std::lround(kWidth / aspect)));
  json doc = {{"version", 1},
              {"render", {{"width", kWidth}, {"height", height}, {"spp", 64}}},
              {"camera", camera},
              {"objects", json::array({{{"type", "gltf"}, {"file", file}}})}};
  bool lit = false;
  for (const GltfLight& l : asset->lights) lit = lit || l.type != GltfLightType::kSpot;
  // Without lights of its own, a neutral white sky: the asset's colours as they are.
  if (!lit) doc["environment"] = {{"radiance", json::array({1, 1, 1})}};
  return doc.dump(2);
}

LoadResult load_gltf_scene_file(const std::string& path, const Limits& limits,
                                std::span<const RenderOverride> overrides) {
  LoadResult result;
  const std::string text = gltf_scene_document(path, limits, &result);
  if (text.empty()) return result;
  AssetFolder assets;
  assets.root = fs::absolute(fs::path(path)).parent_path();
  assets.max_file_bytes = std::max<int64_t>(assets.max_file_bytes, limits.max_mesh_file_bytes);
  return load_scene(text, limits, overrides, assets);
}

}  // namespace penumbra::api
