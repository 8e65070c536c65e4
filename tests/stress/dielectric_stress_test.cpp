// Dielectrics under stress: total internal reflection, an index-matched (ior = 1) object is
// invisible, nested spheres, thin slabs, touching and coincident surfaces. Each check is a number
// (a furnace value, a closed-form transmittance, or equality with another render) and no pixel is
// NaN or Inf.
#include <gtest/gtest.h>

#include "tests/stress/stress_util.h"

namespace penumbra::test {
namespace {

constexpr float kGlassIor = 1.5f;

// Inside a uniform environment of radiance 1, a scene of non-absorbing dielectrics and
// albedo-1 opaque surfaces renders 1 wherever paths can escape (energy conserved, none created).
void expect_furnace_one(const SceneInput& in, int spp, double tol, const char* what,
                        IntegratorKind kind = IntegratorKind::kPath) {
  RenderSettings s = settings(24, 24, spp);
  s.integrator = kind;
  const RenderResult r = render_input(in, s);
  EXPECT_EQ(nonfinite_count(r), 0) << what;
  const MeanAndError m = image_mean(r);
  EXPECT_NEAR(m.mean, 1.0, tol + 4.0 * m.stderr_of_mean) << what;
}

SceneInput furnace(float fov = 30.f) {
  SceneInput in;
  in.camera = camera_looking({0.3f, 0.5f, 4.f}, {0, 0, 0}, fov);
  in.environment = Spectrum(1.f);
  return in;
}

DielectricParams glass(float roughness = 0.f, float ior = kGlassIor) {
  return DielectricParams{ior, roughness, Spectrum(0.f)};
}

// A right-angle glass prism: light entering a leg face at normal incidence meets the hypotenuse
// at 45 degrees, beyond the critical angle asin(1/1.5) = 41.8 degrees, and is totally reflected
// out through the other leg. The camera looks into one leg; the only light is an emitter (radiance
// 1) facing the other leg. Expected radiance: T(0)^2 = (1 - ((n-1)/(n+1))^2)^2 = 0.9216 plus
// multiply reflected paths of order R^2 T^2 ~ 0.0015. Without TIR the pixel would be ~0.
TEST(DielectricStress, TotalInternalReflectionInAPrism) {
  for (float scale : {1e-3f, 1.f, 1e3f}) {
    SceneInput in;
    // Prism cross-section in x-y: legs along +x and +y from the origin, hypotenuse from (1,0) to
    // (0,1); extruded along z over [-1, 1].
    MeshDesc m;
    const float z0 = -1.f, z1 = 1.f;
    m.positions = {vec3(0, 0, z0), vec3(1, 0, z0), vec3(0, 1, z0), vec3(0, 0, z1), vec3(1, 0, z1), vec3(0, 1, z1)};
    for (vec3& q : m.positions) q *= scale;
    // Counter-clockwise seen from outside: ends (z0, z1), leg y=0, leg x=0, hypotenuse.
    m.indices = {0, 2, 1, 3, 4, 5, 0, 1, 4, 0, 4, 3, 0, 3, 5, 0, 5, 2, 1, 2, 5, 1, 5, 4};
    ObjectDesc prism;
    prism.shape = std::move(m);
    prism.material = 0;
    in.materials = {glass(), DiffuseParams{Spectrum(0.f)}};
    // Camera below the y = 0 leg, looking up (+y) into it near x = 0.3.
    in.camera = camera_looking(vec3(0.3f, -3.f, 0.f) * scale, vec3(0.3f, 0.f, 0.f) * scale, 2.f, {0, 0, 1});
    // The emitter faces the x = 0 leg from the -x side (front = u x v points +x).
    in.objects = {prism, quad(vec3(-3.f, -2.f, -2.f) * scale, vec3(0, 6, 0) * scale, vec3(0, 0, 4) * scale, 1,
                              Spectrum(1.f))};
    const RenderResult r = render_input(in, settings(8, 8, 64));
    EXPECT_EQ(nonfinite_count(r), 0);
    const MeanAndError me = image_mean(r);
    const double r0 = std::pow((kGlassIor - 1.0) / (kGlassIor + 1.0), 2.0);
    const double expected = (1 - r0) * (1 - r0);
    EXPECT_GT(me.mean, expected - 0.003) << "scale " << scale;
    EXPECT_LT(me.mean, expected + 0.004) << "scale " << scale;
  }
}

// ior = 1 is no interface at all: the image equals the scene without the object (within noise;
// shadow rays do not pass dielectrics, so light arrives through it by BSDF sampling instead).
TEST(DielectricStress, IndexMatchedGlassIsInvisible) {
  SceneInput base;
  base.camera = camera_looking({0, 1.2f, 3.f}, {0, 0.4f, 0}, 40.f);
  base.materials = {DiffuseParams{Spectrum(0.7f, 0.5f, 0.3f)}, glass(0.f, 1.f), glass(0.4f, 1.f)};
  base.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0),
                  quad({-1.5f, 2.5f, 1.5f}, {0, 0, -3}, {3, 0, 0}, 0, Spectrum(2.f))};
  for (uint32_t mat : {1u, 2u}) {
    SceneInput with = base;
    with.objects.push_back(sphere({0, 0.5f, 0}, 0.5f, mat));
    with.objects.push_back(box({-1.2f, 0.05f, -0.2f}, {-0.6f, 0.6f, 0.4f}, mat));  // not coincident with the floor
    // Unlimited depth: crossing the invisible surfaces adds path segments, which a depth cap
    // would count.
    const RenderResult a = render_input(base, settings(32, 32, 256, -1, 1));
    const RenderResult b = render_input(with, settings(32, 32, 256, -1, 2));
    EXPECT_EQ(nonfinite_count(b), 0);
    const BlockComparison cmp = compare_blocks(a, b, 8, 4.5, 0.01);
    EXPECT_EQ(cmp.bad, 0) << (mat == 1 ? "smooth" : "rough") << " ior 1: " << cmp.first_bad
                          << " (worst " << cmp.worst_sigma << " sigma)";
  }
}

TEST(DielectricStress, GlassSphereInsideGlassSphereInFurnace) {
  SceneInput in = furnace();
  in.materials = {glass(), glass(0.f, 1.33f)};
  in.objects = {sphere({0, 0, 0}, 1.f, 0), sphere({0.2f, 0.1f, 0}, 0.5f, 1)};
  expect_furnace_one(in, 128, 0.01, "nested smooth spheres");
  expect_furnace_one(in, 128, 0.01, "nested smooth spheres, distributed", IntegratorKind::kDistributed);
}

// A slab 1e-4 thick (and 1e-6 relative to its distance) in a furnace: every refraction exit is
// found, or paths would die inside and darken it.
TEST(DielectricStress, ThinSlabInFurnace) {
  for (float thickness : {1e-2f, 1e-4f}) {
    SceneInput in = furnace(20.f);
    in.materials = {glass()};
    in.objects = {box({-1, -1, -thickness / 2}, {1, 1, thickness / 2}, 0)};
    in.camera = camera_looking({0.4f, 0.9f, 4.f}, {0, 0, 0}, 20.f);
    expect_furnace_one(in, 64, 0.005, "thin slab");
  }
}

// Touching and coincident surfaces: two glass spheres touching in one point, a glass box sharing
// a face with an albedo-1 box, a glass sphere resting on an albedo-1 floor, and two coincident
// albedo-1 quads. All non-absorbing, so the furnace stays at 1.
TEST(DielectricStress, TouchingAndCoincidentSurfacesInFurnace) {
  SceneInput in = furnace(40.f);
  in.materials = {glass(), DiffuseParams{Spectrum(1.f)}, glass(0.3f)};
  in.objects = {sphere({-0.5f, 0.5f, 0}, 0.5f, 0),
                sphere({0.5f, 0.5f, 0}, 0.5f, 2),
                box({-0.5f, 0.f, 0.6f}, {0.f, 0.5f, 1.1f}, 0),
                box({0.f, 0.f, 0.6f}, {0.5f, 0.5f, 1.1f}, 1),
                quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 1),
                quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 1)};
  in.camera = camera_looking({0.5f, 1.5f, 3.5f}, {0, 0.4f, 0.3f}, 40.f);
  // (Path tracing only: the distributed integrator ends paths at diffuse surfaces, so an albedo-1
  // floor that sees other objects is below 1 there by design.)
  expect_furnace_one(in, 128, 0.01, "touching");
}

// Coincident faces of two different glass boxes (same geometry twice): whichever is hit, nothing
// is created or lost.
TEST(DielectricStress, CoincidentGlassBoxesInFurnace) {
  SceneInput in = furnace(30.f);
  in.materials = {glass(), glass(0.2f, 1.33f)};
  in.objects = {box({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, 0), box({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, 1)};
  RenderSettings s = settings(24, 24, 128);
  const RenderResult r = render_input(in, s);
  EXPECT_EQ(nonfinite_count(r), 0);
  const MeanAndError m = image_mean(r);
  // Rough glass loses some single-scattering energy; never more than 1.
  EXPECT_LT(m.mean, 1.0 + 4 * m.stderr_of_mean + 0.002);
  EXPECT_GT(m.mean, 0.9);
}

}  // namespace
}  // namespace penumbra::test
