// The wavefront driver (renderer/render/wavefront_integrator.h: batches of paths a bounce at a
// time, rays in 16-wide Embree packets) against the scalar driver (integrator.cpp: one path, one
// ray at a time): per path they take the same steps with the same sampler dimensions and the
// film adds their results in the same order, so every image, variance and layer is identical to
// the bit, on every example and accuracy scene (meshes, instances, textures, normal maps,
// environment maps, motion, lens, glass, every light kind), with both integrators.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "tests/stress/stress_util.h"

namespace penumbra::test {
namespace {

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

void expect_same_render(const Scene& scene, RenderSettings s, const std::string& what) {
  s.wavefront = true;
  const RenderResult wave = render(scene, s);
  s.wavefront = false;
  const RenderResult scalar = render(scene, s);
  EXPECT_TRUE(same_floats(wave.image.rgb, scalar.image.rgb)) << what << ": image";
  EXPECT_TRUE(same_floats(wave.variance.rgb, scalar.variance.rgb)) << what << ": variance";
  ASSERT_EQ(wave.layers.size(), scalar.layers.size()) << what;
  for (size_t i = 0; i < wave.layers.size(); ++i)
    EXPECT_TRUE(same_floats(wave.layers[i].data, scalar.layers[i].data)) << what << ": layer " << wave.layers[i].name;
  EXPECT_EQ(wave.stats.rays, scalar.stats.rays) << what;
  EXPECT_EQ(wave.stats.camera_samples, scalar.stats.camera_samples) << what;
}

std::vector<std::filesystem::path> scene_files() {
  std::vector<std::filesystem::path> files;
  const std::filesystem::path root(PENUMBRA_SOURCE_DIR);
  for (const char* dir : {"scenes", "tests/accuracy/scenes"})
    for (const auto& e : std::filesystem::directory_iterator(root / dir))
      if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(WavefrontDriver, SameImagesAsTheScalarDriverOnEveryExampleAndAccuracyScene) {
  const auto files = scene_files();
  ASSERT_GE(files.size(), 20u);
  for (const auto& file : files) {
    const api::LoadResult loaded = api::load_scene_file(file.string());
    ASSERT_TRUE(loaded.ok()) << file;
    const auto scene = Scene::build(loaded.request->scene);
    RenderSettings s = loaded.request->settings;
    // Small, a few samples, every layer.
    const float aspect = float(s.height) / float(std::max(1, s.width));
    s.width = 24;
    s.height = std::max(1, int(24 * aspect));
    s.spp = 5;
    s.noise_threshold = 0.f;
    s.time_limit = 0.0;
    s.denoise = false;
    s.outputs = kOutputAlbedo | kOutputNormal | kOutputDepth;
    for (IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
      s.integrator = kind;
      s.time_limit = 0.0;  // a uniform render of 4 samples: correlated multi-jittered points
      s.spp = 4;
      expect_same_render(*scene, s, file.filename().string() + (kind == IntegratorKind::kPath ? " path" : " distributed"));
      s.time_limit = 1e6;  // 5 samples (not a power of two: the Sobol points) in passes of 1, 1, 2,
                           // 1 (a time budget, never reached)
      s.spp = 5;
      expect_same_render(*scene, s, file.filename().string() + (kind == IntegratorKind::kPath ? " path" : " distributed") + " sobol");
    }
  }
}

// A pixel's samples that do not fit one batch (1024 paths) continue in the next batch on a fresh
// sampler of the same pixel; adaptive sampling, a window and several threads change which samples
// share a batch.
TEST(WavefrontDriver, SameImagesAcrossBatchesAdaptiveSamplingAndWindows) {
  const std::filesystem::path root(PENUMBRA_SOURCE_DIR);
  const api::LoadResult loaded = api::load_scene_file((root / "tests/accuracy/scenes/glass_rough.json").string());
  ASSERT_TRUE(loaded.ok());
  const auto scene = Scene::build(loaded.request->scene);
  RenderSettings s = loaded.request->settings;
  s.width = 6;
  s.height = 5;
  s.spp = 700;  // passes up to 256 samples per pixel: batches split inside pixels
  s.threads = 2;
  expect_same_render(*scene, s, "700 spp");
  s.width = 32;
  s.height = 24;
  s.spp = 64;
  s.noise_threshold = 0.05f;
  expect_same_render(*scene, s, "adaptive");
  s.window = PixelWindow{5, 3, 21, 17};
  s.tile_size = 7;
  expect_same_render(*scene, s, "adaptive in a window");
}

// Coincident quads (each traced by its own parallelogram test, shapes/parallelogram.h): a
// duplicated floor of two colours, and two identical boxes of glass quads; and a duplicated
// sphere of two colours (user geometry too). Their hits tie in t,
// and which one a ray gets must not depend on the order of Embree's traversal, which differs
// between packets and single rays.
TEST(WavefrontDriver, SameImagesWithCoincidentSurfaces) {
  SceneInput in;
  in.camera = camera_looking({0.3f, 1.5f, 4.f}, {0.f, 0.3f, 0.f}, 40.f);
  in.environment = Spectrum(0.6f);
  in.materials = {DiffuseParams{Spectrum(0.8f, 0.2f, 0.2f)}, DiffuseParams{Spectrum(0.2f, 0.2f, 0.8f)},
                  DielectricParams{}};
  in.objects = {quad_object({-3, 0, 3}, {6, 0, 0}, {0, 0, -6}, 0),
                quad_object({-3, 0, 3}, {6, 0, 0}, {0, 0, -6}, 1)};
  for (int copy = 0; copy < 2; ++copy)
    for (const ObjectDesc& face : quad_box(vec3(-0.5f, 0.2f, -0.5f), vec3(0.5f, 1.2f, 0.5f), 2))
      in.objects.push_back(face);
  // And a duplicated sphere of two colours (the sphere's test ties alike).
  in.objects.push_back(sphere(vec3(1.1f, 0.4f, 0.6f), 0.4f, 0));
  in.objects.push_back(sphere(vec3(1.1f, 0.4f, 0.6f), 0.4f, 1));
  in.lights = {PointLightDesc{vec3(1.f, 3.f, 1.f), Spectrum(20.f)}};
  const auto scene = Scene::build(in);
  RenderSettings s;
  s.width = 32;
  s.height = 32;
  s.spp = 8;
  s.max_depth = 8;
  for (IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
    s.integrator = kind;
    expect_same_render(*scene, s, kind == IntegratorKind::kPath ? "path" : "distributed");
  }
}

}  // namespace
}  // namespace penumbra::test
