// The feature mask the scene build computes: `textures` (spheres then compute the uv of their
// hits, ShapeContext::need_uv) is set exactly when some material reads a texture or a normal map,
// or some emission is textured. `lights` and `mis_lights`: whether the distributed and the path
// integrator sample lights, the path integrator leaving a constant environment to BSDF sampling.
#include <gtest/gtest.h>

#include "renderer/scene/scene.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

SceneInput sphere_scene(const MaterialParams& material) {
  SceneInput in;
  in.camera = CameraDesc{{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40.f, 0.f, 3.f, 0.f, 0.f};
  in.materials = {material};
  ObjectDesc sphere;
  sphere.shape = SphereDesc{vec3(0.f), 1.f};
  in.objects = {sphere};
  in.environment = Spectrum(1.f);
  return in;
}

TEST(SceneFeatures, TexturesOnlyWhenSomethingReadsTheUv) {
  TempFolder dir("scene_features_textures");
  const std::string png = dir.file("checker.png");
  write_test_image(png, 2, 2, 3, std::vector<float>(12, 0.5f), OIIO::TypeDesc::UINT8);
  ImageTextureDesc texture;
  texture.path = png;

  EXPECT_FALSE(Scene::build(sphere_scene(DiffuseParams{Spectrum(0.5f)}))->features().textures);

  DiffuseParams coloured;
  coloured.color_texture = texture;
  EXPECT_TRUE(Scene::build(sphere_scene(coloured))->features().textures);

  ConductorParams normal_mapped;
  normal_mapped.normal_map = texture;
  normal_mapped.normal_map->colorspace = TextureColorspace::kLinear;
  EXPECT_TRUE(Scene::build(sphere_scene(normal_mapped))->features().textures);

  SceneInput emitter = sphere_scene(DiffuseParams{Spectrum(0.5f)});
  emitter.objects[0].emission = Spectrum(1.f);
  emitter.objects[0].emission_texture = texture;
  EXPECT_TRUE(Scene::build(emitter)->features().textures);
}

TEST(SceneFeatures, PathIntegratorLeavesOnlyTheConstantEnvironmentOut) {
  // A constant environment alone: every light for the distributed integrator, none for the path.
  const auto env_only = Scene::build(sphere_scene(DiffuseParams{Spectrum(0.5f)}));
  EXPECT_TRUE(env_only->features().lights);
  EXPECT_FALSE(env_only->features().mis_lights);
  EXPECT_FALSE(env_only->light_sampler().empty());
  EXPECT_TRUE(env_only->mis_light_sampler().empty());
  EXPECT_EQ(env_only->mis_light_sampler().pmf(env_only->environment_light()), 0.f);

  // Beside an emitter: the path integrator samples the emitter alone.
  SceneInput both = sphere_scene(DiffuseParams{Spectrum(0.5f)});
  ObjectDesc emitter;
  emitter.shape = SphereDesc{vec3(0.f, 3.f, 0.f), 0.5f};
  emitter.emission = Spectrum(4.f);
  both.objects.push_back(emitter);
  const auto scene = Scene::build(both);
  EXPECT_TRUE(scene->features().mis_lights);
  const int env = scene->environment_light(), light = scene->object(1).light;
  EXPECT_GT(scene->light_sampler().pmf(env), 0.f);
  EXPECT_EQ(scene->mis_light_sampler().pmf(env), 0.f);
  EXPECT_EQ(scene->mis_light_sampler().pmf(light), 1.f);

  // An environment map is sampled by its luminance, which BSDF sampling does not follow: it stays.
  SceneInput mapped = sphere_scene(DiffuseParams{Spectrum(0.5f)});
  mapped.environment = Spectrum(0.f);
  EnvironmentMapDesc map;
  map.width = 4;
  map.height = 2;
  map.rgb = std::make_shared<const std::vector<float>>(
      std::vector<float>{1, 1, 1, 9, 9, 9, 1, 1, 1, 1, 1, 1, 2, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1});
  mapped.environment_map = map;
  const auto with_map = Scene::build(mapped);
  EXPECT_TRUE(with_map->features().mis_lights);
  EXPECT_EQ(with_map->mis_light_sampler().pmf(with_map->environment_light()), 1.f);
}

}  // namespace
}  // namespace penumbra::test
