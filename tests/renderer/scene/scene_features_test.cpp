// The feature mask the scene build computes: `textures` (spheres then compute the uv of their
// hits, ShapeContext::need_uv) is set exactly when some material reads a texture or a normal map,
// or some emission is textured.
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

}  // namespace
}  // namespace penumbra::test
