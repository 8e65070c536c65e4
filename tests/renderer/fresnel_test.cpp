// Fresnel equations, the diffuse Fresnel fits, Gauss-Legendre nodes and GGX normalisation.
#include <gtest/gtest.h>

#include "renderer/fresnel.h"
#include "renderer/microfacet.h"
#include "tests/renderer/bsdf_test_util.h"

namespace penumbra {
namespace {

TEST(FresnelDielectric, KnownValues) {
  EXPECT_NEAR(fresnel_dielectric(1.f, 1.5f).reflectance, 0.04f, 1e-6f);
  EXPECT_NEAR(fresnel_dielectric(-1.f, 1.5f).reflectance, 0.04f, 1e-6f);
  EXPECT_EQ(fresnel_dielectric(0.3f, 1.f).reflectance, 0.f);
  // Brewster angle: p-polarised reflectance vanishes, F = R_s / 2.
  const float tb = std::atan(1.5f), ci = std::cos(tb), ct = std::cos(std::asin(std::sin(tb) / 1.5f));
  const float rs = (ci - 1.5f * ct) / (ci + 1.5f * ct);
  EXPECT_NEAR(fresnel_dielectric(ci, 1.5f).reflectance, 0.5f * rs * rs, 1e-6f);
  // Inside beyond the critical angle (41.8 degrees for 1.5): total internal reflection.
  EXPECT_EQ(fresnel_dielectric(-std::cos(test::deg(45.f)), 1.5f).reflectance, 1.f);
  EXPECT_LT(fresnel_dielectric(-std::cos(test::deg(40.f)), 1.5f).reflectance, 1.f);
  EXPECT_EQ(fresnel_dielectric(0.f, 1.5f).reflectance, 1.f);
}

TEST(FresnelDielectric, StokesSymmetryAndSnell) {
  for (float t = 0.f; t < 89.5f; t += 0.5f) {
    const float ci = std::cos(test::deg(t));
    const auto out = fresnel_dielectric(ci, 1.5f);
    ASSERT_LT(out.cos_t, 0.f);
    const float si = std::sqrt(1.f - ci * ci), st = std::sqrt(1.f - out.cos_t * out.cos_t);
    ASSERT_NEAR(st, si / 1.5f, 1e-5f);  // Snell
    // The same pair of angles seen from inside reflects the same fraction.
    const auto in = fresnel_dielectric(out.cos_t, 1.5f);
    ASSERT_NEAR(in.reflectance, out.reflectance, 5e-5f);
    ASSERT_NEAR(in.cos_t, ci, 1e-5f);
    ASSERT_FLOAT_EQ(out.eta_it, 1.5f);
    ASSERT_FLOAT_EQ(in.eta_it, 1.f / 1.5f);
  }
}

TEST(FresnelDiffuseReflectance, MatchesNumericalIntegral) {
  for (float eta : {1.2f, 1.33f, 1.5f, 1.8f}) {
    for (float e : {eta, 1.f / eta}) {
      // 2 \int_0^1 F(mu) mu dmu, midpoint rule.
      double sum = 0.0;
      const int n = 200000;
      for (int i = 0; i < n; ++i) {
        const float mu = (i + 0.5f) / n;
        sum += 2.0 * fresnel_dielectric(mu, e).reflectance * mu / n;
      }
      EXPECT_NEAR(fresnel_diffuse_reflectance(e), sum, 0.01 * sum) << "eta " << e;
    }
  }
}

TEST(MicrofacetGaussLegendre, IntegratesPolynomialsExactly) {
  std::vector<double> x, w;
  gauss_legendre(16, x, w);
  double s0 = 0, s30 = 0;
  for (int i = 0; i < 16; ++i) s0 += w[i], s30 += w[i] * std::pow(x[i], 30);
  EXPECT_NEAR(s0, 2.0, 1e-12);
  EXPECT_NEAR(s30, 2.0 / 31.0, 1e-12);
}

TEST(MicrofacetGgx, NormalisedAndVisibleNormalsNormalised) {
  for (float alpha : {0.01f, 0.1f, 0.5f, 1.f}) {
    const GgxDistribution d(alpha);
    const vec3 wi = test::spherical(test::deg(70.f), 0.f);
    double proj = 0.0, vis = 0.0;
    // \int D(m) cos dm = 1 and \int D_wi(m) dm = 1, integrated in (cos theta, phi).
    test::AdaptiveCubature c1([&](double c, double phi) {
      const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
      return double(d.ndf(vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c)))) * c;
    });
    test::AdaptiveCubature c2([&](double c, double phi) {
      const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
      return double(d.pdf_visible(wi, vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c))));
    });
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j) {
        proj += c1.integrate(i / 8.0, (i + 1) / 8.0, j * M_PI / 4, (j + 1) * M_PI / 4, 1e-8);
        vis += c2.integrate(i / 8.0, (i + 1) / 8.0, j * M_PI / 4, (j + 1) * M_PI / 4, 1e-8);
      }
    EXPECT_NEAR(proj, 1.0, 2e-3) << alpha;
    EXPECT_NEAR(vis, 1.0, 2e-3) << alpha;
  }
}

}  // namespace
}  // namespace penumbra
