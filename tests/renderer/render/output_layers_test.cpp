// Output layers (albedo, normal, depth) against closed-form answers: a diffuse plane facing the
// camera gives its colour, its normal and its distance along the view axis exactly; a pixel
// split between two surfaces gives the mean of the two; the beauty image does not change.
#include <gtest/gtest.h>

#include "renderer/render/output_layers.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

const Spectrum kColorA(0.2f, 0.4f, 0.6f);
const Spectrum kColorB(0.9f, 0.1f, 0.3f);

// Camera at z = 3 looking down -z; a large quad in the plane z = 0 facing it.
SceneInput facing_plane() {
  SceneInput in;
  in.camera = camera_looking({0, 0, 3}, {0, 0, 0}, 40.f);
  in.materials = {DiffuseParams{kColorA}};
  in.objects = {quad_object({-10, -10, 0}, {20, 0, 0}, {0, 20, 0}, 0)};
  in.environment = Spectrum(0.5f);
  return in;
}

const ImageLayer& layer(const RenderResult& r, const char* name) {
  for (const ImageLayer& l : r.layers)
    if (l.name == name) return l;
  ADD_FAILURE() << "no layer " << name;
  static const ImageLayer none;
  return none;
}

const float* at(const ImageLayer& l, int width, int x, int y) {
  return &l.data[(size_t(y) * width + x) * size_t(l.channels)];
}

constexpr uint32_t kAll = kOutputAlbedo | kOutputNormal | kOutputDepth;

TEST(OutputLayers, DiffusePlaneFacingTheCameraIsExact) {
  RenderSettings s = small_settings(9, 7, 8, 4);
  s.outputs = kAll;
  const RenderResult r = render_input(facing_plane(), s);
  ASSERT_EQ(r.layers.size(), 3u);
  EXPECT_EQ(r.layers[0].name, "albedo");
  EXPECT_EQ(r.layers[1].name, "normal");
  EXPECT_EQ(r.layers[2].name, "depth");
  EXPECT_EQ(r.layers[2].channels, 1);
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(at(layer(r, "albedo"), s.width, x, y)[c], kColorA[c], 1e-6f);
      const float* n = at(layer(r, "normal"), s.width, x, y);
      EXPECT_NEAR(n[0], 0.f, 1e-6f);
      EXPECT_NEAR(n[1], 0.f, 1e-6f);
      EXPECT_NEAR(n[2], 1.f, 1e-6f);
      // z-depth, not the distance along the ray (which grows towards the corners): 3 everywhere.
      EXPECT_NEAR(at(layer(r, "depth"), s.width, x, y)[0], 3.f, 1e-5f) << x << "," << y;
    }
}

TEST(OutputLayers, OnlyTheRequestedLayersInBitOrder) {
  RenderSettings s = small_settings(4, 4, 2, 2);
  s.outputs = kOutputDepth | kOutputAlbedo;
  const RenderResult r = render_input(facing_plane(), s);
  ASSERT_EQ(r.layers.size(), 2u);
  EXPECT_EQ(r.layers[0].name, "albedo");
  EXPECT_EQ(r.layers[1].name, "depth");
  s.outputs = 0;
  EXPECT_TRUE(render_input(facing_plane(), s).layers.empty());
}

// Width 9: the middle pixel column spans film x in [4, 5), and the image centre (x = 0 in the
// scene, the two quads' common edge, at both depths) is its middle: half its samples see A at
// depth 3, half see B at depth 4.
TEST(OutputLayers, PixelSplitBetweenTwoSurfacesIsTheMeanOverSamples) {
  SceneInput in = facing_plane();
  in.materials = {DiffuseParams{kColorA}, DiffuseParams{kColorB}};
  in.objects = {quad_object({-10, -10, 0}, {10, 0, 0}, {0, 20, 0}, 0),
                quad_object({0, -10, -1}, {10, 0, 0}, {0, 20, 0}, 1)};
  RenderSettings s = small_settings(9, 5, 1024, 2);
  s.outputs = kAll;
  const RenderResult r = render_input(in, s);
  const float* a = at(layer(r, "albedo"), s.width, 4, 2);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], 0.5f * (kColorA[c] + kColorB[c]), 0.01f) << c;
  EXPECT_NEAR(at(layer(r, "depth"), s.width, 4, 2)[0], 3.5f, 0.01f);
  EXPECT_NEAR(at(layer(r, "normal"), s.width, 4, 2)[2], 1.f, 1e-5f);
  // The neighbours are wholly one or the other.
  EXPECT_NEAR(at(layer(r, "albedo"), s.width, 3, 2)[0], kColorA[0], 1e-6f);
  EXPECT_NEAR(at(layer(r, "albedo"), s.width, 5, 2)[0], kColorB[0], 1e-6f);
  EXPECT_NEAR(at(layer(r, "depth"), s.width, 5, 2)[0], 4.f, 1e-5f);
}

// Where the camera sees the environment: albedo its colour clamped to [0, 1], normal 0, depth
// the finite background value; at a silhouette the depth is the surface's, not a blend.
TEST(OutputLayers, BackgroundAndSilhouettes) {
  SceneInput in = facing_plane();
  in.environment = Spectrum(2.f, 0.5f, 0.25f);
  in.objects = {quad_object({-10, -10, 0}, {10, 0, 0}, {0, 20, 0}, 0)};  // left half only
  RenderSettings s = small_settings(9, 5, 64, 2);
  s.outputs = kAll;
  const RenderResult r = render_input(in, s);
  const float* a = at(layer(r, "albedo"), s.width, 7, 2);
  EXPECT_FLOAT_EQ(a[0], 1.f);
  EXPECT_FLOAT_EQ(a[1], 0.5f);
  EXPECT_FLOAT_EQ(a[2], 0.25f);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(at(layer(r, "normal"), s.width, 7, 2)[c], 0.f);
  EXPECT_EQ(at(layer(r, "depth"), s.width, 7, 2)[0], kBackgroundDepth);
  EXPECT_NEAR(at(layer(r, "depth"), s.width, 4, 2)[0], 3.f, 1e-5f);
  EXPECT_NEAR(at(layer(r, "normal"), s.width, 4, 2)[2], 0.5f, 0.05f);
  for (const ImageLayer& l : r.layers)
    for (float v : l.data) ASSERT_TRUE(std::isfinite(v)) << l.name;
}

// OIDN's conventions per material: glass 1, a conductor its reflectance at normal incidence,
// a plastic its base colour; the normal faces the camera even on a quad's back.
TEST(OutputLayers, AlbedoPerMaterialAndNormalFacesTheViewer) {
  SceneInput in = facing_plane();
  in.objects = {quad_object({-10, -10, 0}, {0, 20, 0}, {20, 0, 0}, 0)};  // its back faces the camera
  RenderSettings s = small_settings(3, 3, 4, 3);
  s.outputs = kAll;
  in.materials = {DielectricParams{}};
  RenderResult r = render_input(in, s);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(at(layer(r, "albedo"), 3, 1, 1)[c], 1.f);
  EXPECT_NEAR(at(layer(r, "normal"), 3, 1, 1)[2], 1.f, 1e-6f);
  ConductorParams metal;
  metal.color = Spectrum(0.9f, 0.6f, 0.2f);
  metal.roughness = 0.3f;
  in.materials = {metal};
  r = render_input(in, s);
  EXPECT_FLOAT_EQ(at(layer(r, "albedo"), 3, 1, 1)[1], 0.6f);
  EXPECT_NEAR(at(layer(r, "normal"), 3, 1, 1)[2], 1.f, 1e-6f);
  PlasticParams plastic;
  plastic.color = Spectrum(0.3f, 0.2f, 0.1f);
  in.materials = {plastic};
  r = render_input(in, s);
  EXPECT_FLOAT_EQ(at(layer(r, "albedo"), 3, 1, 1)[0], 0.3f);
}

// Asking for layers changes nothing in the beauty image, for either integrator, with adaptive
// sampling, and the layers do not depend on the thread count.
TEST(OutputLayers, BeautyIsBitIdenticalAndLayersIndependentOfThreads) {
  SceneInput in = facing_plane();
  in.materials = {DiffuseParams{kColorA}, ConductorParams{Spectrum(0.8f), 0.2f}};
  in.objects.push_back(sphere_object({0.3f, 0.2f, 0.6f}, 0.5f, 1));
  in.objects.push_back(quad_object({-1, 2, 1}, {2, 0, 0}, {0, 0, 1}, 0, Spectrum(5.f)));
  for (const IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed})
    for (const float threshold : {0.f, 0.1f}) {
      RenderSettings s = small_settings(24, 16, 40, 6);
      s.integrator = kind;
      s.noise_threshold = threshold;
      s.threads = 2;
      s.tile_size = 5;
      const RenderResult plain = render_input(in, s);
      s.outputs = kAll;
      const RenderResult with = render_input(in, s);
      EXPECT_EQ(plain.image.rgb, with.image.rgb);
      EXPECT_EQ(plain.stats.rays, with.stats.rays);
      s.threads = 1;
      s.tile_size = 16;
      const RenderResult one = render_input(in, s);
      ASSERT_EQ(one.layers.size(), 3u);
      for (size_t i = 0; i < 3; ++i) EXPECT_EQ(one.layers[i].data, with.layers[i].data) << i;
    }
}

}  // namespace
}  // namespace penumbra::test
