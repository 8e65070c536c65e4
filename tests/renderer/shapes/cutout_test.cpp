// Cutouts (glTF alphaMode MASK): a triangle mesh with an alpha texture exists only where
// factor x alpha(uv) >= cutoff; camera and shadow rays pass through the holes alike.
#include <gtest/gtest.h>

#include "renderer/scene/scene.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

// A unit square in the z = 0 plane facing +z, uv (0, 0) at its top-left (x = 0, y = 1).
SceneInput cutout_scene(const std::string& png, float factor, float cutoff) {
  SceneInput in;
  in.camera = CameraDesc{{0.5f, 0.5f, 3}, {0.5f, 0.5f, 0}, {0, 1, 0}, 40.f, 0.f, 3.f, 0.f, 0.f};
  in.materials = {DiffuseParams{Spectrum(0.5f)}};
  ObjectDesc square;
  square.shape = MeshDesc{{vec3(0, 0, 0), vec3(1, 0, 0), vec3(1, 1, 0), vec3(0, 1, 0)},
                          {0, 1, 2, 0, 2, 3},
                          {},
                          {vec2(0, 1), vec2(1, 1), vec2(1, 0), vec2(0, 0)}};
  ImageTextureDesc alpha;
  alpha.path = png;
  alpha.channel = 3;
  alpha.filter = TextureFilter::kNearest;
  square.alpha_texture = alpha;
  square.alpha_factor = factor;
  square.alpha_cutoff = cutoff;
  in.objects = {square};
  in.environment = Spectrum(1.f);
  return in;
}

TEST(Cutout, RaysPassWhereAlphaIsBelowTheCutout) {
  TempFolder dir("cutout");
  const std::string png = dir.file("half.png");
  // 2 x 1 RGBA: the left texel opaque (alpha 1), the right one alpha 0.4.
  write_test_image(png, 2, 1, 4, {1, 1, 1, 1, 1, 1, 1, 0.4f}, OIIO::TypeDesc::UINT8);
  const auto scene = Scene::build(cutout_scene(png, 1.f, 0.5f));
  SurfaceHit hit;
  const vec3 down(0, 0, -1);
  EXPECT_TRUE(scene->intersect(Ray{vec3(0.25f, 0.5f, 1), down}, &hit));
  EXPECT_FALSE(scene->intersect(Ray{vec3(0.75f, 0.5f, 1), down}, &hit));
  EXPECT_TRUE(scene->occluded(vec3(0.25f, 0.5f, 1), down, 2.f, 0.f));
  EXPECT_FALSE(scene->occluded(vec3(0.75f, 0.5f, 1), down, 2.f, 0.f));
  // The factor multiplies: 0.4 x 2 = 0.8 >= 0.5 makes the right half solid too.
  const auto doubled = Scene::build(cutout_scene(png, 2.f, 0.5f));
  EXPECT_TRUE(doubled->intersect(Ray{vec3(0.75f, 0.5f, 1), down}, &hit));
}

}  // namespace
}  // namespace penumbra::test
