// Extreme parameters: roughness 0 / 1e-4 / just above the smooth cut-off / 1, emission 1e6,
// lights of tiny area, a million samples in one pixel, degenerate triangles and zero-length
// normals in meshes, extreme fields of view and apertures. Each test checks a number; no pixel
// is ever NaN or Inf.
#include <gtest/gtest.h>

#include "tests/stress/stress_util.h"

namespace penumbra::test {
namespace {


// Roughness 1e-4 maps to GGX alpha 1e-8, below the smooth cut-off (alpha 1e-4): it must render
// exactly as roughness 0. Roughness 0.0101 (alpha just above the cut-off) is the sharpest rough
// lobe: its NEE pdfs are ~1e8; it must render as the smooth one within noise. Roughness 1 is the
// widest lobe. In a furnace: never above 1, and = 1 for the (near-)smooth ones.
TEST(Extremes, RoughnessZeroTinyAndOne) {
  struct Family {
    const char* name;
    MaterialParams (*make)(float);
    double min_at_one;  // energy left at roughness 1 (single-scattering GGX loses some)
    double rough_vs_smooth;  // the rough model's difference from the smooth one near alpha 0
  };
  const Family families[] = {
      {"conductor", [](float r) -> MaterialParams { return ConductorParams{Spectrum(1.f), r}; }, 0.5, 0.01},
      {"dielectric", [](float r) -> MaterialParams { return DielectricParams{1.5f, r, Spectrum(0.f)}; }, 0.3, 0.01},
      {"plastic", [](float r) -> MaterialParams { return PlasticParams{Spectrum(1.f), 1.5f, r}; }, 0.3, 0.03},
  };
  for (const Family& f : families) {
    const RenderResult smooth = render_input(furnace_with_sphere(f.make(0.f)), settings(16, 16, 64));
    const RenderResult tiny = render_input(furnace_with_sphere(f.make(1e-4f)), settings(16, 16, 64));
    EXPECT_EQ(smooth.image.rgb, tiny.image.rgb) << f.name << ": roughness 1e-4 is smooth";
    for (float r : {0.0101f, 1.f}) {
      const RenderResult img = render_input(furnace_with_sphere(f.make(r)), settings(16, 16, 128));
      EXPECT_EQ(nonfinite_count(img), 0) << f.name << " r " << r;
      const MeanAndError m = image_mean(img);
      EXPECT_LT(m.mean, 1.0 + 4 * m.stderr_of_mean + 0.002) << f.name << " r " << r;
      if (r < 0.5f) {
        const MeanAndError ms = image_mean(smooth);
        // (The rough plastic averages its internal reflectance over Mitsuba 3's table nodes,
        // which underestimates it; the smooth one integrates it exactly: they differ by ~1.5%.)
        EXPECT_NEAR(m.mean, ms.mean, f.rough_vs_smooth + 4 * m.stderr_of_mean) << f.name << " r " << r;
      } else {
        EXPECT_GT(m.mean, f.min_at_one) << f.name;
      }
    }
  }
}

// A near-delta conductor floor reflecting a small bright sphere light and a point light: the
// highlight comes through MIS between a 1e8 BSDF pdf and light sampling; no NaN/Inf, and the mean
// matches the smooth mirror within noise.
TEST(Extremes, SharpestGlossyHighlightHasNoInfinities) {
  auto scene = [](float roughness) {
    SceneInput in;
    in.camera = camera_looking({0, 1, 3}, {0, 0.3f, 0}, 40.f);
    in.materials = {ConductorParams{Spectrum(0.9f), roughness}, DiffuseParams{Spectrum(0.5f)}};
    in.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0), sphere({0, 1.f, -1.f}, 0.1f, 1, Spectrum(50.f)),
                  quad({-2, 0, -1.5f}, {4, 0, 0}, {0, 2, 0}, 1)};
    in.lights = {PointLightDesc{{0.5f, 1.5f, 0.f}, Spectrum(5.f)}};
    return in;
  };
  const RenderResult a = render_input(scene(0.f), settings(32, 32, 256, 6));
  const RenderResult b = render_input(scene(0.0101f), settings(32, 32, 256, 6));
  EXPECT_EQ(nonfinite_count(a), 0);
  EXPECT_EQ(nonfinite_count(b), 0);
  const MeanAndError ma = image_mean(a), mb = image_mean(b);
  EXPECT_NEAR(mb.mean, ma.mean, 0.02 * ma.mean + 4 * std::hypot(ma.stderr_of_mean, mb.stderr_of_mean));
}

// Radiance is linear in emission: with a single light the paths are the same whatever its
// strength, so emission 1e6 gives exactly 1e6 times the image of emission 1 (to float rounding).
TEST(Extremes, EmissionOneMillionIsLinear) {
  auto scene = [](float e) {
    SceneInput in;
    in.camera = camera_looking({0, 1.5f, 3}, {0, 0.5f, 0}, 45.f);
    in.materials = {DiffuseParams{Spectrum(0.6f)}, DielectricParams{1.5f, 0.2f, Spectrum(0.f)}};
    in.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0), sphere({0, 0.4f, 0}, 0.4f, 1),
                  quad({-0.2f, 1.5f, 0.2f}, {0, 0, -0.4f}, {0.4f, 0, 0}, 0, Spectrum(e))};
    return in;
  };
  const RenderResult one = render_input(scene(1.f), settings(24, 24, 32, 8));
  const RenderResult big = render_input(scene(1e6f), settings(24, 24, 32, 8));
  EXPECT_EQ(nonfinite_count(big), 0);
  int bad = 0, lit = 0;
  for (size_t i = 0; i < one.image.rgb.size(); ++i) {
    const double a = one.image.rgb[i], b = big.image.rgb[i];
    if (a > 0) ++lit;
    if (std::abs(b - 1e6 * a) > 1e-4 * 1e6 * a + 1e-30) ++bad;
  }
  EXPECT_GT(lit, int(one.image.rgb.size() / 2));
  EXPECT_EQ(bad, 0);
}

// A sphere light of radius 1e-4 or 1e-6 (radiance I / (pi r^2)) lights a floor as a point light
// of intensity I does: same image within noise. (Sampling by solid angle must not lose the cone
// of a tiny sphere to the cancellation in 1 - cos(theta_max).)
TEST(Extremes, TinySphereLightEqualsPointLight) {
  const vec3 pos(0.2f, 1.f, 0.f);
  const float intensity = 2.f;
  SceneInput base;
  base.camera = camera_looking({0, 2, 2.5f}, {0, 0, 0}, 45.f);
  base.materials = {DiffuseParams{Spectrum(0.7f)}};
  base.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0)};
  SceneInput point = base;
  point.lights = {PointLightDesc{pos, Spectrum(intensity)}};
  const RenderResult ref = render_input(point, settings(32, 32, 64, 2));
  for (float r : {1e-4f, 1e-6f}) {
    SceneInput tiny = base;
    tiny.objects.push_back(sphere(pos, r, 0, Spectrum(intensity / (kPi * r * r))));
    const RenderResult img = render_input(tiny, settings(32, 32, 64, 2));
    EXPECT_EQ(nonfinite_count(img), 0) << r;
    const BlockComparison cmp = compare_blocks(ref, img, 8, 5.0, 0.01);
    EXPECT_EQ(cmp.bad, 0) << "radius " << r << ": " << cmp.first_bad;
  }
}

// A quad light 1e-4 on a side gives the far field of a 1e-2 one with the same power.
TEST(Extremes, TinyQuadLightEqualsSmallQuadLight) {
  auto scene = [](float side, float radiance) {
    SceneInput in;
    in.camera = camera_looking({0, 2, 2.5f}, {0, 0, 0}, 45.f);
    in.materials = {DiffuseParams{Spectrum(0.7f)}};
    in.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0),
                  quad(vec3(-side / 2, 1.f, side / 2), {0, 0, -side}, {side, 0, 0}, 0, Spectrum(radiance))};
    return in;
  };
  const RenderResult ref = render_input(scene(1e-2f, 1e4f), settings(32, 32, 64, 2));
  const RenderResult tiny = render_input(scene(1e-4f, 1e8f), settings(32, 32, 64, 2));
  EXPECT_EQ(nonfinite_count(tiny), 0);
  const BlockComparison cmp = compare_blocks(ref, tiny, 8, 5.0, 0.01);
  EXPECT_EQ(cmp.bad, 0) << cmp.first_bad;
}

// One pixel at a million samples: a convex diffuse object of albedo 0.5 in a uniform environment
// of radiance 1 reflects exactly 0.5 (it sees only the sky). The Sobol indices run to 1e6, the
// film accumulates in double, and the estimate converges to 1e-3.
TEST(Extremes, OneMillionSamplesInOnePixel) {
  SceneInput in;
  in.camera = camera_looking({0, 0, 4}, {0, 0, 0}, 1.f);
  in.environment = Spectrum(1.f);
  in.materials = {DiffuseParams{Spectrum(0.5f)}};
  in.objects = {sphere({0, 0, 0}, 1.f, 0)};
  const RenderResult r = render_input(in, settings(1, 1, 1'000'000));
  EXPECT_EQ(nonfinite_count(r), 0);
  EXPECT_EQ(r.stats.spp_min, 1'000'000);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.image.rgb[c], 0.5, 1e-3);
}

std::string mesh_json(const std::string& positions, const std::string& indices, const std::string& normals) {
  return R"({"version": 1,
    "render": {"width": 24, "height": 24, "spp": 16, "max_depth": 4},
    "camera": {"position": [0, 1.5, 3], "look_at": [0, 0, 0], "fov": 40},
    "materials": {"m": {"type": "diffuse", "color": [0.7, 0.7, 0.7]}},
    "objects": [{"type": "mesh", "material": "m", "positions": [)" +
         positions + "], \"indices\": [" + indices + "]" + (normals.empty() ? "" : ", \"normals\": [" + normals + "]") +
         R"(}],
    "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": [2, 2, 2]}]})";
}

// Degenerate triangles inside a mesh (a repeated vertex, three collinear vertices) are skipped
// with a warning, not fatal, and the image equals the mesh without them.
TEST(Extremes, DegenerateTrianglesInAMeshAreSkipped) {
  const std::string pos = "-1,0,1, 1,0,1, 1,0,-1, -1,0,-1, 0,0,0";
  const std::string clean = mesh_json(pos, "0,1,2, 0,2,3", "");
  const std::string dirty = mesh_json(pos, "0,1,2, 0,0,1, 0,4,2, 0,2,3, 3,3,3", "");
  const api::LoadResult loaded = api::load_scene(dirty);
  ASSERT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors[0].to_string());
  EXPECT_FALSE(loaded.warnings.empty());
  const RenderResult a = render_json(clean), b = render_json(dirty);
  EXPECT_EQ(nonfinite_count(b), 0);
  EXPECT_EQ(a.image.rgb, b.image.rgb);

  // Straight into the renderer (no loader clean-up): Embree skips them, the emitter sampler never
  // picks a zero-area triangle, nothing is NaN.
  SceneInput in;
  in.camera = camera_looking({0, 1.5f, 3}, {0, 0, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.7f)}};
  MeshDesc m;
  m.positions = {vec3(-1, 0, 1), vec3(1, 0, 1), vec3(1, 0, -1), vec3(-1, 0, -1), vec3(0, 0, 0)};
  m.indices = {0, 1, 2, 0, 0, 1, 0, 4, 2, 0, 2, 3, 3, 3, 3};
  ObjectDesc floor;
  floor.shape = m;
  ObjectDesc lamp;
  MeshDesc lm = m;
  for (vec3& p : lm.positions) p = vec3(p.x * 0.3f, 1.5f, -p.z * 0.3f);  // flipped: faces down
  lamp.shape = lm;
  lamp.emission = Spectrum(3.f);
  in.objects = {floor, lamp};
  const RenderResult r = render_input(in, settings(24, 24, 64, 4));
  EXPECT_EQ(nonfinite_count(r), 0);
  SceneInput clean_in = in;
  for (ObjectDesc& o : clean_in.objects) std::get<MeshDesc>(o.shape).indices = {0, 1, 2, 0, 2, 3};
  const RenderResult ref = render_input(clean_in, settings(24, 24, 64, 4));
  EXPECT_GT(image_mean(ref).mean, 0.005);
  const BlockComparison cmp = compare_blocks(ref, r, 8, 5.0, 0.01);
  EXPECT_EQ(cmp.bad, 0) << cmp.first_bad;
}

// Zero-length shading normals: the loader repairs them (with a warning); the renderer, given them
// directly, falls back to the geometric normal, so the image equals the mesh without normals.
TEST(Extremes, ZeroLengthNormals) {
  const std::string pos = "-1,0,1, 1,0,1, 1,0,-1, -1,0,-1";
  const std::string with_zero = mesh_json(pos, "0,1,2, 0,2,3", "0,0,0, 0,1,0, 0,0,0, 0,1,0");
  const api::LoadResult loaded = api::load_scene(with_zero);
  ASSERT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors[0].to_string());
  EXPECT_FALSE(loaded.warnings.empty());
  const RenderResult a = render_json(mesh_json(pos, "0,1,2, 0,2,3", "")), b = render_json(with_zero);
  EXPECT_EQ(nonfinite_count(b), 0);
  EXPECT_EQ(a.image.rgb, b.image.rgb);

  SceneInput in;
  in.camera = camera_looking({0, 1.5f, 3}, {0, 0, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.7f)}};
  in.lights = {DirectionalLightDesc{{0.3f, -1, -0.2f}, Spectrum(2.f)}};
  MeshDesc m;
  m.positions = {vec3(-1, 0, 1), vec3(1, 0, 1), vec3(1, 0, -1), vec3(-1, 0, -1)};
  m.indices = {0, 1, 2, 0, 2, 3};
  ObjectDesc plain;
  plain.shape = m;
  m.normals = std::vector<vec3>(4, vec3(0.f));
  ObjectDesc zero;
  zero.shape = m;
  SceneInput in_zero = in;
  in.objects = {plain};
  in_zero.objects = {zero};
  const RenderResult c = render_input(in, settings(24, 24, 16, 4));
  const RenderResult d = render_input(in_zero, settings(24, 24, 16, 4));
  EXPECT_EQ(nonfinite_count(d), 0);
  EXPECT_EQ(c.image.rgb, d.image.rgb);
}

// fov 0.01 degrees: 24 pixels span 4e-6 rad; every pixel still sees the lit floor exactly.
// fov 179 degrees inside a furnace: every pixel is 1, even at the extreme edges.
TEST(Extremes, ExtremeFieldOfView) {
  {
    SceneInput in;
    in.camera = camera_looking({0, 3, 3}, {0, 0, 0}, 0.01f);
    in.materials = {DiffuseParams{Spectrum(1.f)}};
    in.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0)};
    in.lights = {DirectionalLightDesc{{0, -1, 0}, Spectrum(1.f)}};
    const RenderResult r = render_input(in, settings(24, 24, 4, 2));
    EXPECT_EQ(nonfinite_count(r), 0);
    for (float v : r.image.rgb) ASSERT_NEAR(v, 1.0 / kPi, 1e-5);
  }
  for (float fov : {179.f, 179.99f}) {
    SceneInput in;
    in.camera = camera_looking({0, 0, 0}, {0, 0, -1}, fov);
    in.environment = Spectrum(1.f);
    in.materials = {DiffuseParams{Spectrum(1.f)}};
    in.objects = {sphere({0, 0, -3}, 1.f, 0), quad({-50, -2, 50}, {100, 0, 0}, {0, 0, -100}, 0)};
    const RenderResult r = render_input(in, settings(32, 24, 64));
    EXPECT_EQ(nonfinite_count(r), 0) << fov;
    const MeanAndError m = image_mean(r);
    EXPECT_NEAR(m.mean, 1.0, 0.005 + 4 * m.stderr_of_mean) << fov;
    double lo = 1e9, hi = -1e9;
    for (float v : r.image.rgb) {
      lo = std::min(lo, double(v));
      hi = std::max(hi, double(v));
    }
    EXPECT_GT(lo, 0.7) << fov;
    EXPECT_LT(hi, 1.3) << fov;
  }
}

// Aperture 1e-7 is a pinhole to within noise; aperture 1e3 (a lens far wider than the scene) in
// a furnace still gives 1 everywhere; a tiny focus distance with a large aperture is finite.
TEST(Extremes, ExtremeApertures) {
  SceneInput in;
  in.camera = camera_looking({0, 1.5f, 3}, {0, 0.3f, 0}, 40.f);
  in.materials = {DiffuseParams{Spectrum(0.7f)}, PlasticParams{Spectrum(0.2f, 0.4f, 0.8f), 1.5f, 0.2f}};
  in.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0), sphere({0, 0.4f, 0}, 0.4f, 1)};
  in.lights = {PointLightDesc{{1, 2, 1}, Spectrum(4.f)}};
  in.environment = Spectrum(0.2f);
  const RenderResult pinhole = render_input(in, settings(32, 32, 64, 4));
  SceneInput tiny = in;
  tiny.camera.aperture_radius = 1e-7f;
  const RenderResult t = render_input(tiny, settings(32, 32, 64, 4));
  EXPECT_EQ(nonfinite_count(t), 0);
  const BlockComparison cmp = compare_blocks(pinhole, t, 8, 5.0, 0.01);
  EXPECT_EQ(cmp.bad, 0) << cmp.first_bad;

  for (float focus : {3.f, 1e-6f, 1e6f}) {
    SceneInput f = furnace_with_sphere(DiffuseParams{Spectrum(1.f)});
    f.camera.aperture_radius = 1e3f;
    f.camera.focus_distance = focus;
    const RenderResult r = render_input(f, settings(16, 16, 64));
    EXPECT_EQ(nonfinite_count(r), 0) << focus;
    const MeanAndError m = image_mean(r);
    EXPECT_NEAR(m.mean, 1.0, 0.005 + 4 * m.stderr_of_mean) << "focus " << focus;
  }
}

}  // namespace
}  // namespace penumbra::test
