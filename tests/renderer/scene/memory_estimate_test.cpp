// The memory estimate counts each mesh's arrays where they live (input, renderer copy, Embree
// buffers), Embree's BVH per triangle, light-sampling tables of emitters, and the film.
#include "renderer/scene/memory_estimate.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

MeshDesc grid_mesh(int quads, bool normals, bool uvs) {
  MeshDesc m;
  for (int i = 0; i <= quads; ++i)
    for (int j = 0; j < 2; ++j) {
      m.positions.emplace_back(float(i), float(j), 0.f);
      if (normals) m.normals.emplace_back(0.f, 0.f, 1.f);
      if (uvs) m.uvs.emplace_back(float(i), float(j));
    }
  for (uint32_t i = 0; i < uint32_t(quads); ++i)
    m.indices.insert(m.indices.end(), {2 * i, 2 * i + 2, 2 * i + 3, 2 * i, 2 * i + 3, 2 * i + 1});
  return m;
}

TEST(MemoryEstimate, MeshArraysAndEmbree) {
  const MeshDesc plain = grid_mesh(500, false, false);  // 1002 vertices, 1000 triangles
  const MemoryEstimate e = estimate_mesh_memory(plain);
  EXPECT_EQ(e.scene_input, 1002 * 12 + 1000 * 12);
  EXPECT_EQ(e.shapes, e.scene_input + 1000 * 12);  // and a static mesh's face normals
  // Vertex and index buffers, and at least the measured 61 bytes of BVH per triangle.
  EXPECT_GE(e.embree, 1002 * 12 + 1000 * 12 + 1000 * 61);
  EXPECT_LE(e.embree, 1002 * 12 + 1000 * 12 + 1000 * 80);
  EXPECT_GT(e.embree_build_peak, 0);
  EXPECT_EQ(e.film, 0);
  const MemoryEstimate full = estimate_mesh_memory(grid_mesh(500, true, true));
  EXPECT_EQ(full.scene_input - e.scene_input, 1002 * (12 + 8));
}

TEST(MemoryEstimate, SceneAddsEmittersMotionAndFilm) {
  SceneInput scene;
  ObjectDesc mesh;
  mesh.shape = grid_mesh(100, false, false);
  scene.objects.push_back(mesh);
  scene.objects.push_back(ObjectDesc{SphereDesc{}});
  RenderSettings settings;
  settings.width = 100;
  settings.height = 50;
  const MemoryEstimate base = estimate_memory(scene, settings);
  EXPECT_EQ(base.film, 100 * 50 * 80);
  EXPECT_EQ(base.total(),
            base.scene_input + base.shapes + base.embree + base.embree_build_peak + base.film);

  scene.objects[0].emission = Spectrum(1.f);  // a triangle-area table for light sampling
  EXPECT_EQ(estimate_memory(scene, settings).shapes - base.shapes, 200 * 4);
  scene.objects[0].emission = Spectrum(0.f);
  scene.objects[0].velocity = vec3(1.f, 0.f, 0.f);  // a second vertex buffer
  const MemoryEstimate moving = estimate_memory(scene, settings);
  EXPECT_EQ(moving.embree - base.embree, 202 * 12);
  EXPECT_EQ(base.shapes - moving.shapes, 200 * 12);  // a moving mesh has no face normals
}

}  // namespace
}  // namespace penumbra::test

namespace penumbra::test {
namespace {

// Copies cost a fixed amount each, and each copied mesh one more BVH (its child scene), however
// many copies and instances objects name it; no vertex buffers are added.
TEST(MemoryEstimate, InstancesAddPerCopyAndOneBvhPerMesh) {
  SceneInput scene;
  ObjectDesc mesh;
  mesh.shape = grid_mesh(500, false, false);  // 1000 triangles
  scene.objects.push_back(mesh);
  const RenderSettings settings;
  const MemoryEstimate base = estimate_memory(scene, settings);
  scene.instances.push_back(InstancesDesc{0, std::vector<InstanceTransform>(10)});
  const MemoryEstimate ten = estimate_memory(scene, settings);
  scene.instances.push_back(InstancesDesc{0, std::vector<InstanceTransform>(990)});
  const MemoryEstimate thousand = estimate_memory(scene, settings);
  EXPECT_EQ(ten.scene_input, base.scene_input);
  EXPECT_EQ(ten.shapes, base.shapes);
  const int64_t per_copy = (thousand.embree - ten.embree) / 990;
  EXPECT_GT(per_copy, 64);
  EXPECT_LT(per_copy, 2048);
  // The second BVH: the measured 61-80 bytes per triangle, once.
  const int64_t bvh = ten.embree - base.embree - 10 * per_copy;
  EXPECT_GE(bvh, 1000 * 61);
  EXPECT_LE(bvh, 1000 * 80);
}

// An environment map's texels count in the input and, with its sampling tables (density, CDF
// and a guide entry per four texels), in the light: about 12 + 21 bytes per texel, or 12 + 9
// where the light shares the input's texels (scale 1, as the api leaves every map).
TEST(MemoryEstimate, EnvironmentMapTexelsAndSamplingTables) {
  SceneInput scene;
  RenderSettings settings;
  settings.width = 0;
  settings.height = 0;
  const MemoryEstimate none = estimate_memory(scene, settings);
  EnvironmentMapDesc map;
  map.width = 1024;
  map.height = 512;
  map.rgb = std::make_shared<const std::vector<float>>(size_t(1024 * 512 * 3), 1.f);
  map.scale = 0.5f;
  scene.environment_map = map;
  const MemoryEstimate e = estimate_memory(scene, settings);
  const int64_t texels = 1024 * 512;
  EXPECT_EQ(e.scene_input - none.scene_input, texels * 12);
  // Texels (12 bytes) and one distribution (8 bytes and a guide entry per four texels): a render
  // builds the full map's or the compensated twin's, not both.
  EXPECT_GE(e.shapes - none.shapes, texels * 21);
  EXPECT_LE(e.shapes - none.shapes, texels * 22);
  EXPECT_EQ(e.embree, none.embree);
  // Scale 1: the light reads the input's texels.
  scene.environment_map->scale = 1.f;
  const MemoryEstimate shared = estimate_memory(scene, settings);
  EXPECT_GE(shared.shapes - none.shapes, texels * 9);
  EXPECT_LE(shared.shapes - none.shapes, texels * 10);
}

}  // namespace
}  // namespace penumbra::test
