#include "renderer/scene/memory_estimate.h"

#include <algorithm>
#include <bit>
#include <variant>
#include <vector>


namespace penumbra {
namespace {

// Embree 3.13.5 (Debian 12), RTC_BUILD_QUALITY_HIGH with RTC_SCENE_FLAG_ROBUST as the scene
// build sets them: its device memory monitor reported 61-64 bytes of BVH per triangle after the
// build, and 33-52 more at the build's peak, for 20 thousand and 1 million triangle meshes
// (docs/mesh-files.md).
constexpr int64_t kBvhBytesPerTriangle = 64;
constexpr int64_t kBvhBuildExtraPerTriangle = 52;
// A copy placed by an instances object: the renderer's Instance (shapes/instance.h) plus
// Embree's instance geometry, its transforms and its share of the top-level BVH. Measured
// (docs/instancing.md): 520-540 resident bytes per copy after the build
// (InstanceMemory.CopiesCostBytesNotTheMesh), 580-800 at the peak of a render
// (bench/instancing_benchmark.sh); the estimate takes the larger.
constexpr int64_t kBytesPerInstance = 800;
// Film::Pixel (2 x 3 doubles + a count, padded to 56) plus the float RGB image and its variance.
constexpr int64_t kFilmBytesPerPixel = 56 + 12 + 12;

int64_t mesh_arrays(const MeshDesc& m) {
  return int64_t(m.positions.size() * sizeof(vec3) + m.normals.size() * sizeof(vec3) +
                 m.uvs.size() * sizeof(vec2) + m.indices.size() * sizeof(uint32_t));
}

void add_mesh(const MeshDesc& mesh, bool emissive, bool moving, MemoryEstimate& e) {
  const int64_t triangles = int64_t(mesh.indices.size() / 3);
  e.scene_input += mesh_arrays(mesh);
  e.shapes += mesh_arrays(mesh) + (emissive ? triangles * int64_t(sizeof(float)) : 0) +
              (moving ? 0 : triangles * int64_t(sizeof(vec3)));  // a static mesh's face normals
  // A moving mesh has at least two vertex buffers (time steps); assume two.
  const int64_t vertex_buffers = moving ? 2 : 1;
  e.embree += vertex_buffers * int64_t(mesh.positions.size() * sizeof(vec3)) +
              int64_t(mesh.indices.size() * sizeof(uint32_t)) + triangles * kBvhBytesPerTriangle;
  e.embree_build_peak += triangles * kBvhBuildExtraPerTriangle;
}

// An environment map: its texels in the input, and in the light (lights/environment_map.h) a
// scaled copy of them unless it shares the input's (scale 1 and two rows or more, as the api's
// maps; the light also copies texels that are not clean, which the api's never are) and one
// sampling distribution (sampling/distribution_2d.h; the full map's or the
// path integrator's compensated twin's, whichever the render samples: each is built on first
// use): per texel a density and a CDF entry, per four texels a guide entry (a row of w texels
// has bit_ceil(w) / 4 + 1), per row sin(theta) and the marginal's entries.
void add_environment_map(const EnvironmentMapDesc& map, MemoryEstimate& e) {
  const int64_t w = std::max(map.width, 0), h = std::max(map.height, 0);
  const int64_t texels = w * h, texel_bytes = 3 * int64_t(sizeof(float));
  e.scene_input += texels * texel_bytes;
  const int64_t guide_per_row =
      (int64_t(std::bit_ceil(uint64_t(std::max<int64_t>(w, 1)))) / 4 + 1) * 4;
  // The row's extra CDF entry, guide, sin(theta), the marginal's entries.
  const int64_t row_bytes = 4 + guide_per_row + 4 + 9;
  const bool shared = map.scale == 1.f && h >= 2;
  e.shapes += texels * ((shared ? 0 : texel_bytes) + 4 + 4) + h * row_bytes;
}

}  // namespace

MemoryEstimate estimate_mesh_memory(const MeshDesc& mesh) {
  MemoryEstimate e;
  add_mesh(mesh, false, false, e);
  return e;
}

MemoryEstimate estimate_memory(const SceneInput& scene, const RenderSettings& settings) {
  MemoryEstimate e;
  for (const ObjectDesc& object : scene.objects)
    if (const auto* mesh = std::get_if<MeshDesc>(&object.shape))
      add_mesh(*mesh, !is_black(object.emission),
               object.velocity != vec3(0.f) || object.acceleration != vec3(0.f), e);
  // Each instanced mesh gets a second BVH (its child scene), sharing its vertex buffers.
  std::vector<bool> copied(scene.objects.size(), false);
  for (const InstancesDesc& set : scene.instances) {
    e.embree += int64_t(set.transforms.size()) * kBytesPerInstance;
    if (set.object >= scene.objects.size() || copied[set.object]) continue;
    copied[set.object] = true;
    if (const auto* mesh = std::get_if<MeshDesc>(&scene.objects[set.object].shape)) {
      const int64_t triangles = int64_t(mesh->indices.size() / 3);
      e.embree += triangles * kBvhBytesPerTriangle;
      e.embree_build_peak = std::max(e.embree_build_peak, triangles * kBvhBuildExtraPerTriangle);
    }
  }
  if (scene.environment_map) add_environment_map(*scene.environment_map, e);
  e.film = int64_t(settings.width) * settings.height * kFilmBytesPerPixel;
  return e;
}

}  // namespace penumbra
