// White furnace per BSDF: the directional albedo \int f |cos| dwo estimated from sample() weights.
// For refraction the energy (not radiance) albedo is what must not exceed 1: radiance weights carry
// 1/eta^2 (Veach 1997 sec. 5.2), so transmitted weights are multiplied back by eta^2 -- equivalently,
// a furnace of radiance 1 outside and eta^2 inside (the equilibrium radiance in a medium) must
// return exactly its own radiance.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "renderer/materials/fresnel.h"
#include "renderer/materials/plastic.h"
#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

struct Albedo {
  double mean = 0.0, stderr_ = 0.0, max_weight = 0.0;
};

Albedo energy_albedo(const Material& mat, const vec3& wi, int n, uint64_t seed) {
  test::Rng rng(seed);
  double sum = 0.0, sum2 = 0.0, mx = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto bs = mat.sample(BsdfContext{}, wi, rng.next(), rng.next2());
    if (!bs) continue;
    double w = bs->weight.x;
    if (bs->lobe & kLobeTransmission) w *= double(bs->eta) * bs->eta;
    sum += w;
    sum2 += w * w;
    mx = std::max(mx, w);
  }
  Albedo a;
  a.mean = sum / n;
  a.stderr_ = std::sqrt(std::max(0.0, sum2 / n - a.mean * a.mean) / n);
  a.max_weight = mx;
  return a;
}

const float kAngles[] = {0.f, 30.f, 60.f, 80.f, 89.f};

TEST(BsdfEnergy, DiffuseWhiteIsExactlyOne) {
  const Material mat(DiffuseParams{Spectrum(1.f)});
  for (float t : kAngles) {
    const Albedo a = energy_albedo(mat, test::spherical(test::deg(t), 0.3f), 20000, 1);
    EXPECT_NEAR(a.mean, 1.0, 1e-6) << t;
    EXPECT_LE(a.max_weight, 1.0 + 1e-6);
  }
}

TEST(BsdfEnergy, SmoothConductorWhiteIsExactlyOne) {
  const Material mat(ConductorParams{Spectrum(1.f), 0.f});
  for (float t : kAngles) {
    const Albedo a = energy_albedo(mat, test::spherical(test::deg(t), 0.3f), 1000, 1);
    EXPECT_NEAR(a.mean, 1.0, 1e-6) << t;
  }
}

TEST(BsdfEnergy, SmoothDielectricConservesEnergyBothSides) {
  for (float ior : {1.33f, 1.5f, 2.4f}) {
    const Material mat(DielectricParams{ior, 0.f, Spectrum(0.f)});
    for (float t : kAngles)
      for (bool inside : {false, true}) {
        const float theta = test::deg(inside ? 180.f - t : t);
        const Albedo a = energy_albedo(mat, test::spherical(theta, 0.3f), 4000, 2);
        // Every single sample carries R/R or T/T: the estimate is exact, not just unbiased.
        EXPECT_NEAR(a.mean, 1.0, 1e-5) << "ior " << ior << " theta " << t << " inside " << inside;
      }
  }
}

TEST(BsdfEnergy, SmoothDielectricRadianceWeights) {
  // From outside at normal incidence, ior 1.5: R = 0.04, T = 0.96, radiance albedo R + T / eta^2.
  const Material mat(DielectricParams{1.5f, 0.f, Spectrum(0.f)});
  const auto t = mat.sample(BsdfContext{kLobeDeltaTransmission}, vec3(0, 0, 1), 0.5f, vec2(0.5f));
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(t->weight.x, 0.96f / 2.25f, 1e-5f);
  // From inside the same pair of directions: the radiance gains eta^2.
  const auto t2 = mat.sample(BsdfContext{kLobeDeltaTransmission}, vec3(0, 0, -1), 0.5f, vec2(0.5f));
  ASSERT_TRUE(t2.has_value());
  EXPECT_NEAR(t2->weight.x, 0.96f * 2.25f, 1e-4f);
}

TEST(BsdfEnergy, RoughConductorNeverGains) {
  // Single-scattering GGX loses the multiply-scattered energy (Kulla & Conty 2017; Heitz et al.
  // 2016). Measured here: r <= 0.3 at <= 30 degrees loses < 2%; at r = 1 (alpha = 1) half of the
  // visible normals reflect below the horizon and the albedo is only ~0.3-0.4.
  for (float r : {0.05f, 0.3f, 0.6f, 1.f}) {
    const Material mat(ConductorParams{Spectrum(1.f), r});
    for (float t : kAngles) {
      const Albedo a = energy_albedo(mat, test::spherical(test::deg(t), 0.3f), 40000, 3);
      EXPECT_LE(a.mean, 1.0 + 4.0 * a.stderr_ + 1e-4) << "r " << r << " theta " << t;
      EXPECT_LE(a.max_weight, 1.0 + 1e-5);
      if (t <= 30.f && r <= 0.3f) {
        EXPECT_GT(a.mean, 0.98) << "r " << r << " theta " << t;
      }
      EXPECT_GT(a.mean, 0.25) << "r " << r << " theta " << t;
    }
  }
}

TEST(BsdfEnergy, RoughDielectricLosesOnlyMultipleScattering) {
  // The single-scattering rough interface loses only what Smith masking removes (light that would
  // scatter again between microfacets). Measured loss (ior 1.5): r <= 0.3 about 1% except at
  // grazing incidence; r = 1: ~15% at normal incidence, ~33% at 60 degrees, ~67% at 89 degrees,
  // ~58% from inside at 170 degrees (internally reflected light is masked). The bounds
  // below allow that and nothing like the "too dark" glass of a missing eta^2 (which loses
  // 1 - 1/2.25 = 56% of the transmitted energy from outside at every angle).
  struct Case {
    float r, theta, min_albedo;
  };
  const Case cases[] = {
      {0.05f, 0.f, 0.995f},  {0.05f, 60.f, 0.99f},  {0.05f, 89.f, 0.7f},
      {0.3f, 0.f, 0.99f},    {0.3f, 60.f, 0.97f},   {0.3f, 89.f, 0.55f},
      {1.f, 0.f, 0.80f},     {1.f, 60.f, 0.62f},    {1.f, 89.f, 0.3f},
      {0.3f, 170.f, 0.97f},  {0.3f, 130.f, 0.97f},  {1.f, 170.f, 0.38f},
      {1.f, 120.f, 0.4f},    {0.05f, 150.f, 0.99f}, {0.05f, 100.f, 0.95f},
  };
  for (const Case& c : cases) {
    const Material mat(DielectricParams{1.5f, c.r, Spectrum(0.f)});
    const Albedo a = energy_albedo(mat, test::spherical(test::deg(c.theta), 0.3f), 40000, 4);
    EXPECT_LE(a.mean, 1.0 + 4.0 * a.stderr_ + 1e-4) << "r " << c.r << " theta " << c.theta;
    EXPECT_LE(a.max_weight, 1.0 + 1e-5) << "r " << c.r << " theta " << c.theta;
    EXPECT_GE(a.mean, c.min_albedo) << "r " << c.r << " theta " << c.theta;
  }
}

// The smooth plastic with a white base conserves energy exactly: its albedo is
// F(mu_i) + (1 - F(mu_i)) (1 - fdr_ext) / (eta^2 (1 - fdr_int)) = 1, because
// eta^2 (1 - fdr_int) = 1 - fdr_ext (radiance / n^2 is invariant, Veach 1997 sec. 5.2). Checked
// deterministically (F plus a midpoint rule over the diffuse lobe) for iors across the whole
// valid range (0, 1e30], normal to grazing incidence. With Mitsuba's polynomial fits for fdr_int
// it was 1.0228 at ior 2.4 (normal incidence), 1.0011 at ior 1.5, 1.0009 at ior 1.01, and at
// ior 4 the fit's fdr_int = 1.0100 > 1 made it negative (-2.18).
TEST(BsdfEnergy, SmoothPlasticWhiteBaseReflectsExactlyOne) {
  for (float ior : {0.3f, 0.5f, 0.9f, 1.0001f, 1.01f, 1.5f, 2.4f, 4.f, 10.f, 1e3f, 1e30f}) {
    const Material mat(PlasticParams{Spectrum(1.f), ior, 0.f});
    for (float t : {0.f, 30.f, 60.f, 80.f, 89.f, 89.9f}) {
      const vec3 wi = test::spherical(test::deg(t), 0.f);
      const int n = 200000;  // ior 0.3 transmits only within cos > 0.954: 9000 nodes there
      double diffuse = 0.0;  // \int f cos dwo = 2 pi \int_0^1 eval(mu_o) dmu_o (isotropic lobe)
      for (int i = 0; i < n; ++i) {
        const float mu = (i + 0.5f) / n;
        diffuse += mat.eval(BsdfContext{}, wi, vec3(std::sqrt(1.f - mu * mu), 0.f, mu)).x;
      }
      const double albedo = fresnel_dielectric(wi.z, ior).reflectance + 2.0 * kPi * diffuse / n;
      EXPECT_NEAR(albedo, 1.0, 1e-5) << "ior " << ior << " theta " << t;
    }
  }
}

// The furnace through sample(), as the integrators use it, for smooth and rough coatings and
// every ior above (below 1 the coating is the thinner medium and light from outside is totally
// reflected beyond the critical angle). The rough coating (single-scattering GGX, Mitsuba's
// tables) may lose energy, never gain it (below ior 1 at small roughness see also the test
// below). Before the rough table's nodes clustered at grazing incidence it gained
// at 89.9 degrees: 1.004 at ior 1.01, 1.001 at ior 1.5 (roughness 0.0101).
TEST(BsdfEnergy, PlasticWhiteBaseNeverGainsAtAnyIor) {
  const float angles[] = {0.f, 30.f, 60.f, 80.f, 89.f, 89.9f};
  for (float ior : {1e-4f, 0.5f, 1.01f, 1.5f, 2.4f, 4.f, 1e3f, 1e30f}) {
    for (float r : {0.f, 0.0101f, 0.05f, 0.3f, 1.f}) {
      if (ior < 1.f && r > 0.f && r < 0.3f) continue;  // more angles in the test below
      const Material mat(PlasticParams{Spectrum(1.f), ior, r});
      CoatingTableCache coatings;
      const PlasticParams params{Spectrum(1.f), ior, r};
      const PlasticBsdf model(params, PlasticBsdf::tables_for(params, coatings));
      for (float t : angles) {
        const vec3 wi = test::spherical(test::deg(t), 0.3f);
        // No NaN anywhere in the range (Material would drop it silently and hide a loss).
        for (float mu : {0.f, 1e-4f, 0.5f, 1.f}) {
          const vec3 wo(std::sqrt(1.f - mu * mu), 0.f, mu);
          ASSERT_TRUE(std::isfinite(model.eval(BsdfContext{}, wi, wo).x))
              << "ior " << ior << " r " << r << " theta " << t << " mu_o " << mu;
        }
        const Albedo a = energy_albedo(mat, wi, 40000, 5);
        EXPECT_LE(a.mean, 1.0 + 4.0 * a.stderr_ + 1e-4)
            << "ior " << ior << " r " << r << " theta " << t;
        // (At ior 1e-4 the transmitting cone, cos > sqrt(1 - ior^2), is narrower than the float
        // spacing below 1: the diffuse part, 4e-4 at normal incidence, is lost, not gained.)
        if (r == 0.f && ior > 1e-3f) {
          EXPECT_NEAR(a.mean, 1.0, 4.0 * a.stderr_ + 1e-4) << "ior " << ior << " theta " << t;
        }
      }
    }
  }
}

// A nearly smooth rough coating thinner than the outside medium (ior < 1): its external
// transmittance t(mu) rises from 0 (total internal reflection) within a foot about alpha wide
// just below the critical cosine. With Mitsuba 3's uniform 64-node table it rendered 1.32 at ior
// 0.5, r 0.0101, 30 degrees; with nodes clustered onto the critical angle (fixed cubic/quadratic)
// still 1.020 +- 0.001 (ior 0.1, r 0.05, 6 degrees), 1.007 (ior 0.3, r 0.1, 18 degrees), 1.003
// (ior 0.5, r 0.1, 30.5 degrees), 1.0006 (ior 0.7, r 0.05): the interpolated t exceeded the
// bound 1 - E_spec by up to 0.019, and Mitsuba's mean for fdr_int made the diffuse factor D up
// to 1.010. Now the nodes are placed adaptively and D = 1 by reciprocity (plastic.cpp). The
// angles: a 4-degree grid plus the listed cases and the critical angle of each ior.
TEST(BsdfEnergy, RoughPlasticBelowIorOneNeverGains) {
  for (float ior : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f}) {
    std::vector<float> angles = {6.f, 18.f, 30.5f};
    for (float t = 0.f; t < 90.f; t += 4.f) angles.push_back(t);
    const float critical = std::asin(ior) * 180.f / float(kPi);
    for (float d : {-2.f, -1.f, -0.5f, 0.f, 0.5f, 1.f, 2.f}) angles.push_back(critical + d);
    for (float r : {0.0101f, 0.05f, 0.1f, 0.2f}) {
      const Material mat(PlasticParams{Spectrum(1.f), ior, r});
      for (float t : angles) {
        const Albedo a = energy_albedo(mat, test::spherical(test::deg(t), 0.3f), 40000, 5);
        EXPECT_LE(a.mean, 1.0 + 4.0 * a.stderr_ + 1e-4)
            << "ior " << ior << " r " << r << " theta " << t;
      }
    }
  }
}

}  // namespace
}  // namespace penumbra::test
