// Textures through the whole renderer: an emitter's texture seen directly shows each texel where
// its uv says (quad uv (s, t) from the origin, texel row 0 at t = 0); a texture of one value
// renders exactly as that constant; a white textured sphere and a normal-mapped one in the white
// furnace neither gain nor (unmapped) lose energy.
#include <gtest/gtest.h>

#include "renderer/lights/light.h"
#include "renderer/shapes/sphere.h"
#include "tests/renderer/render/render_test_util.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

ImageTextureDesc linear_nearest(const std::string& path) {
  ImageTextureDesc d;
  d.path = path;
  d.colorspace = TextureColorspace::kLinear;
  d.filter = TextureFilter::kNearest;
  return d;
}

TEST(RenderTexture, EmitterTextureSeenDirectlyShowsEachTexelAtItsUv) {
  TempFolder dir("render_emitter_texels");
  // Texels, rows from the top of the file: (0,0) = 1  (1,0) = 2
  //                                        (0,1) = 3  (1,1) = 4   (red; green and blue scaled)
  const std::string path = dir.file("e.exr");
  std::vector<float> texels;
  for (float v : {1.f, 2.f, 3.f, 4.f}) texels.insert(texels.end(), {v, 2.f * v, 4.f * v});
  write_test_image(path, 2, 2, 3, texels);
  SceneInput in;
  in.camera = camera_looking({0, 0, 2}, {0, 0, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.f)}};
  // The quad fills the view; its front (u x v = +z) faces the camera; s grows to the right,
  // t upwards, so texel row 0 (t < 0.5) is the bottom half of the picture.
  ObjectDesc quad = quad_object({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 0, Spectrum(1.f));
  quad.emission_texture = linear_nearest(path);
  in.objects = {quad};
  const RenderResult r = render_input(in, small_settings(16, 16, 4, 1));
  struct Probe {
    int x, y;
    float texel;
  };
  for (const Probe& p :
       {Probe{2, 13, 1.f}, Probe{13, 13, 2.f}, Probe{2, 2, 3.f}, Probe{13, 2, 4.f}}) {
    const float* px = r.image.pixel(p.x, p.y);
    EXPECT_NEAR(px[0], p.texel, 1e-5f) << "pixel " << p.x << ", " << p.y;
    EXPECT_NEAR(px[1], 2.f * p.texel, 1e-5f);
    EXPECT_NEAR(px[2], 4.f * p.texel, 1e-5f);
  }
}

TEST(RenderTexture, TextureOfOneValueRendersExactlyAsTheConstant) {
  TempFolder dir("render_uniform");
  const std::string color = dir.file("c.exr"), light = dir.file("l.exr");
  write_test_image(color, 3, 2, 3, std::vector<float>(18, 0.6f));
  write_test_image(light, 2, 2, 1, std::vector<float>(4, 0.5f));
  auto scene = [&](bool textured) {
    SceneInput in;
    in.camera = camera_looking({0, 1, 4}, {0, 0.5f, 0}, 40.f);
    DiffuseParams floor{Spectrum(textured ? 1.f : 0.6f)};
    PlasticParams ball{Spectrum(textured ? 1.f : 0.6f), 1.5f, 0.3f};
    ConductorParams metal{Spectrum(0.9f), textured ? 1.f : 0.5f};
    if (textured) {
      floor.color_texture = linear_nearest(color);
      ball.color_texture = floor.color_texture;
      metal.roughness_texture = linear_nearest(light);
    }
    in.materials = {floor, ball, metal};
    in.objects = {quad_object({-3, 0, 3}, {6, 0, 0}, {0, 0, -6}, 0),
                  sphere_object({-0.6f, 0.5f, 0}, 0.5f, 1),
                  sphere_object({0.6f, 0.5f, 0}, 0.5f, 2)};
    ObjectDesc lamp =
        quad_object({-0.5f, 2.5f, -0.5f}, {1, 0, 0}, {0, 0, 1}, 0, Spectrum(textured ? 16.f : 8.f));
    if (textured) lamp.emission_texture = linear_nearest(light);
    in.objects.push_back(lamp);
    return in;
  };
  for (IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
    RenderSettings s = small_settings(24, 16, 8, 6);
    s.integrator = kind;
    const RenderResult constant = render_input(scene(false), s),
                       textured = render_input(scene(true), s);
    EXPECT_EQ(textured.image.rgb, constant.image.rgb);
    EXPECT_GT(image_stats(constant.image).mean[0], 0.01);
  }
}

// Light from a textured emitter arrives through next-event estimation and through BSDF sampling,
// both looking the texture up where they reach the emitter: a lamp whose left half is black and
// right half 2 lights a floor as a lamp of only the right half with constant emission 2.
TEST(RenderTexture, TexturedEmitterLightsAsTheEquivalentConstantOne) {
  TempFolder dir("render_emitter_halves");
  const std::string path = dir.file("halves.exr");
  write_test_image(path, 2, 1, 1, {0.f, 2.f});
  auto scene = [&](bool textured) {
    SceneInput in;
    in.camera = camera_looking({0, 3, 3}, {0, 0, 0}, 50.f);
    in.materials = {DiffuseParams{Spectrum(0.7f)}};
    in.objects = {quad_object({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0)};
    // The lamp faces down (u x v = -y); s runs along +x.
    ObjectDesc lamp = textured ? quad_object({-1, 1, -0.5f}, {2, 0, 0}, {0, 0, 1}, 0, Spectrum(1.f))
                               : quad_object({0, 1, -0.5f}, {1, 0, 0}, {0, 0, 1}, 0, Spectrum(2.f));
    if (textured) lamp.emission_texture = linear_nearest(path);
    in.objects.push_back(lamp);
    return in;
  };
  const RenderResult textured = render_input(scene(true), small_settings(16, 16, 256, 2));
  const RenderResult constant = render_input(scene(false), small_settings(16, 16, 256, 2));
  // Compare the lit floor under the lamp's two halves (pixels not showing the lamp itself).
  for (const auto& [x0, x1] : {std::pair{1, 7}, std::pair{9, 15}}) {
    double a, sa, b, sb;
    region_mean(textured, x0, 10, x1, 15, 0, &a, &sa);
    region_mean(constant, x0, 10, x1, 15, 0, &b, &sb);
    EXPECT_NEAR(a, b, 4.0 * std::sqrt(sa * sa + sb * sb)) << "columns " << x0 << ".." << x1;
    EXPECT_GT(b, 0.01);
  }
}

// Light samples on a textured emissive sphere carry the radiance of the texel under them (the
// scene build asks the sphere for the uv of its samples only when its emission is textured).
TEST(RenderTexture, TexturedSphereEmitterSamplesSeeTheirTexel) {
  TempFolder dir("render_sphere_emitter");
  const std::string path = dir.file("halves.exr");
  write_test_image(path, 2, 1, 1, {1.f, 3.f});
  SceneInput in;
  in.camera = camera_looking({0, 0, 5}, {0, 0, 0}, 30.f);
  in.materials = {DiffuseParams{}};
  ObjectDesc ball = sphere_object({0, 0, 0}, 1.f, 0, Spectrum(2.f));
  ball.emission_texture = linear_nearest(path);
  in.objects = {ball};
  const auto scene = Scene::build(in);
  const Light& light = scene->light(0);
  int left = 0, right = 0;
  for (int i = 0; i < 64; ++i) {
    LightSample ls;
    const vec2 u((float(i % 8) + 0.5f) / 8.f, (float(i / 8) + 0.5f) / 8.f);
    ASSERT_TRUE(light.sample(vec3(0.5f, 0.3f, 4.f), 0.f, u, &ls));
    const float expected = sphere_uv(ls.n).x < 0.5f ? 2.f : 6.f;
    EXPECT_EQ(ls.value, Spectrum(expected));
    (expected == 2.f ? left : right)++;
  }
  EXPECT_GT(left, 0);
  EXPECT_GT(right, 0);
}

TEST(RenderTexture, WhiteTexturedSphereInTheFurnaceRendersOne) {
  TempFolder dir("render_furnace_white");
  const std::string png = dir.file("white.png");
  write_test_image(png, 4, 4, 3, std::vector<float>(48, 1.f), OIIO::TypeDesc::UINT8);
  DiffuseParams white{Spectrum(1.f)};
  white.color_texture = ImageTextureDesc{png};  // sRGB 255 decodes to exactly 1
  const RenderResult r = render_input(furnace_with_sphere(white), small_settings(24, 24, 64));
  const ImageStats st = image_stats(r.image);
  EXPECT_EQ(st.nonfinite, 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(st.mean[c], 1.0, 0.01);
}

TEST(RenderTexture, NormalMappedSphereInTheFurnaceGainsNothing) {
  TempFolder dir("render_furnace_normal");
  const std::string path = dir.file("n.exr");
  // A bumpy map: normals tilted up to ~35 degrees in a pattern of 8 x 8 texels.
  std::vector<float> texels;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const vec3 n =
          glm::normalize(vec3(0.7f * std::sin(float(x)), 0.7f * std::cos(float(y)), 1.f));
      texels.insert(texels.end(), {0.5f * (n.x + 1.f), 0.5f * (n.y + 1.f), 0.5f * (n.z + 1.f)});
    }
  write_test_image(path, 8, 8, 3, texels);
  DiffuseParams white{Spectrum(1.f)};
  white.normal_map = ImageTextureDesc{path, TextureColorspace::kLinear};
  const RenderResult r = render_input(furnace_with_sphere(white), small_settings(24, 24, 64));
  const ImageStats st = image_stats(r.image);
  EXPECT_EQ(st.nonfinite, 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(st.mean[c], 1.0 + 0.01);
    EXPECT_GT(st.mean[c], 0.8);  // the shadowing term and lost directions take a little
  }
}

}  // namespace
}  // namespace penumbra::test
