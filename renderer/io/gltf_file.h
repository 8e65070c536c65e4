#pragma once
// glTF 2.0 assets (.gltf with its buffers and images, .glb) read from untrusted bytes through
// tinygltf (Debian's libtinygltf-dev 2.7, compiled here without its image decoder: images stay
// encoded and are decoded later by OpenImageIO, renderer/io/image_reader.h).
//
// What is read: the default scene's node hierarchy (TRS or matrix, depth-first, cycles and
// depth capped), triangle meshes (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN; POSITION, NORMAL,
// TEXCOORD_0; any index type), metallic-roughness materials with their textures, the first
// camera, KHR_lights_punctual lights, KHR_materials_emissive_strength. Every accessor is checked
// against its buffer view and buffer before a byte is read; every count against the limits
// before anything is allocated from it. Files the asset names (buffers, images) come only
// through the caller's `GltfFileSource`, which confines them (api/gltf_parser.cpp). Errors throw
// GltfError "<name>: <reason>", naming the file and the glTF element (`meshes[2].primitives[0]`).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/textures/texture_desc.h"

namespace penumbra {

struct GltfError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct GltfLimits {
  int64_t max_file_bytes = int64_t(1) << 30;   // the .gltf / .glb and each file it names
  int64_t max_total_bytes = int64_t(2) << 30;  // everything read for one asset
  int64_t max_vertices = 12'000'000;           // over all meshes, as stored (before placement)
  int64_t max_triangles = 4'000'000;
  int64_t max_placed_triangles = 4'000'000;    // over all node instances (each node a copy)
  int max_nodes_visited = 100'000;             // node visits while walking the hierarchy
  int max_depth = 64;                          // node hierarchy and JSON nesting
  int max_images = 4096;
};

// Reads a file the asset names, by its URI (percent-decoded, relative to the asset's folder).
// Returns false with a reason when the file may not or cannot be read (outside the folder,
// missing, too large): the loader then fails naming the URI.
using GltfFileSource = std::function<bool(const std::string& uri, std::vector<uint8_t>* bytes,
                                          std::string* reason)>;

// An image as the asset stores it, still encoded (PNG or JPEG): decoded by the scene build.
struct GltfImage {
  std::string name;  // how errors name it: "helmet.glb: images[3]" or the file's URI
  std::shared_ptr<const std::vector<uint8_t>> bytes;
  std::string extension;  // "png" or "jpg": the OpenImageIO reader to decode it with
};

struct GltfTextureRef {
  int image = -1;  // index into GltfAsset::images
  TextureWrap wrap = TextureWrap::kRepeat;
  TextureFilter filter = TextureFilter::kBilinear;
  float scale = 1.f;  // normalTexture.scale
};

enum class GltfAlphaMode { kOpaque, kMask, kBlend };

struct GltfMaterial {
  std::string name;
  Spectrum base_color{1.f};
  float alpha = 1.f;
  float metallic = 1.f;
  float roughness = 1.f;
  Spectrum emissive{0.f};  // factor x KHR_materials_emissive_strength
  std::optional<GltfTextureRef> base_color_texture;
  std::optional<GltfTextureRef> metallic_roughness_texture;  // G roughness, B metallic
  std::optional<GltfTextureRef> normal_texture;
  std::optional<GltfTextureRef> emissive_texture;
  GltfAlphaMode alpha_mode = GltfAlphaMode::kOpaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
};

// One primitive as stored, in the mesh's own space.
struct GltfPrimitive {
  std::vector<vec3> positions;
  std::vector<vec3> normals;  // empty or one per position
  std::vector<vec2> uvs;      // empty or one per position (TEXCOORD_0)
  std::vector<uint32_t> indices;
  int material = -1;  // -1: glTF's default material
};

struct GltfMesh {
  std::string name;
  std::vector<GltfPrimitive> primitives;
};

// A node that places a mesh: the mesh in world space is to_world * (its own coordinates).
struct GltfMeshInstance {
  int mesh = 0;
  int node = 0;
  glm::dmat4 to_world{1.0};
  std::string node_name;
};

struct GltfCamera {
  std::string name;
  glm::dmat4 to_world{1.0};  // looks down -z, +y up (glTF)
  bool perspective = true;
  double yfov = 0.8;          // radians
  double aspect_ratio = 0.0;  // 0: not given
  double ymag = 1.0;          // orthographic half height
};

enum class GltfLightType { kPoint, kSpot, kDirectional };

struct GltfLight {
  std::string name;
  GltfLightType type = GltfLightType::kPoint;
  Spectrum color{1.f};
  double intensity = 1.0;   // candela (point, spot) or lux (directional)
  double range = 0.0;       // 0: infinite
  double inner_cone = 0.0;  // radians (spot)
  double outer_cone = kPi / 4.0;
  glm::dmat4 to_world{1.0};  // shines along -z from the origin
};

struct GltfAsset {
  std::vector<GltfMesh> meshes;
  std::vector<GltfMeshInstance> instances;  // in hierarchy order
  std::vector<GltfMaterial> materials;
  std::vector<GltfImage> images;
  std::vector<GltfCamera> cameras;  // the cameras placed by nodes, in hierarchy order
  std::vector<GltfLight> lights;    // placed lights, in hierarchy order
  std::vector<std::string> warnings;
  int64_t file_bytes = 0;  // everything read
};

// Parses `bytes` (a .glb when they start with "glTF", else .gltf JSON). `name` is how messages
// name the asset. Throws GltfError.
GltfAsset read_gltf(const std::vector<uint8_t>& bytes, const std::string& name,
                    const GltfFileSource& files, const GltfLimits& limits = {});

// True for ".gltf" and ".glb" (case-insensitive).
bool is_gltf_file_name(const std::string& path);

}  // namespace penumbra
