// Fresnel equations, the hemispherical (diffuse) Fresnel averages, Gauss-Legendre nodes and GGX
// normalisation.
#include <gtest/gtest.h>

#include "renderer/materials/fresnel.h"
#include "renderer/materials/microfacet.h"
#include "renderer/core/quadrature.h"
#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
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

// Brute force: 2 \int_0^1 F(mu) mu dmu by the midpoint rule on 10^6 cosines, straight through
// fresnel_dielectric (so total internal reflection is whatever it says beyond the critical angle;
// the rule's error at that kink is ~h^1.5 = 1e-9).
double brute_force_fdr(float eta) {
  const int n = 1000000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double mu = (i + 0.5) / n;
    sum += double(fresnel_dielectric(float(mu), eta).reflectance) * mu;
  }
  return 2.0 * sum / n;
}

TEST(FresnelDiffuse, MatchesBruteForceIntegral) {
  for (float eta : {1.01f, 1.2f, 1.33f, 1.5f, 1.8f, 2.4f, 4.f, 10.f}) {
    for (float e : {eta, 1.f / eta}) {
      const DiffuseFresnel d = fresnel_diffuse(e);
      EXPECT_NEAR(d.reflectance, brute_force_fdr(e), 1e-5) << "eta " << e;
      EXPECT_NEAR(d.reflectance + d.transmittance, 1.0, 1e-15) << "eta " << e;
    }
  }
  EXPECT_EQ(fresnel_diffuse(1.0).reflectance, 0.0);  // an index-matched interface is invisible
}

TEST(FresnelDiffuse, KnownValues) {
  // Checked independently (midpoint rule on 2e6 cosines, double precision): ior 1.5 gives
  // fdr_ext = 0.091778 and fdr_int = 0.596346; the polynomial fits Mitsuba uses give 0.091774
  // (d'Eon & Irving) and 0.596811 (Egan & Hilgeman), and at eta = 1/2.4 0.86655 for 0.86288.
  EXPECT_NEAR(fresnel_diffuse(1.5).reflectance, 0.0917780, 1e-6);
  EXPECT_NEAR(fresnel_diffuse(1.0 / 1.5).reflectance, 0.5963458, 1e-6);
  EXPECT_NEAR(fresnel_diffuse(2.4).reflectance, 0.2101813, 1e-6);
  EXPECT_NEAR(fresnel_diffuse(1.0 / 2.4).reflectance, 0.8628787, 1e-6);
}

// The relation that makes a white diffuse base under a smooth coating return all its energy:
// radiance / n^2 is invariant (Veach 1997 sec. 5.2), so the diffuse transmittance from inside is
// that from outside over eta^2. Checked against the brute-force integrals, and for every ior the
// scene format accepts, (0, 1e30]: finite, in [0, 1], monotone in eta.
TEST(FresnelDiffuse, InternalTransmittanceIsExternalOverEtaSquared) {
  for (float eta : {1.2f, 1.5f, 2.4f, 4.f}) {
    const double ext = 1.0 - brute_force_fdr(eta), in = 1.0 - brute_force_fdr(1.f / eta);
    EXPECT_NEAR(in * eta * eta / ext, 1.0, 2e-5) << eta;
  }
  double previous = 1.0;
  for (double eta = 1.0; eta <= 1e30; eta *= 1.7) {
    const DiffuseFresnel ext = fresnel_diffuse(eta), in = fresnel_diffuse(1.0 / eta);
    ASSERT_TRUE(std::isfinite(ext.transmittance) && std::isfinite(in.transmittance)) << eta;
    ASSERT_GT(in.transmittance, 0.0) << eta;
    ASSERT_LE(ext.transmittance, previous) << eta;
    ASSERT_GE(ext.reflectance, 0.0) << eta;
    ASSERT_LE(in.reflectance, 1.0) << eta;
    EXPECT_NEAR(in.transmittance * eta * eta / ext.transmittance, 1.0, 1e-12) << eta;
    previous = ext.transmittance;
  }
  // Far from 1 the transmittance falls as 16 / (3 eta) (the leading term of its expansion).
  EXPECT_NEAR(fresnel_diffuse(1e30).transmittance * 1e30, 16.0 / 3.0, 1e-9);
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
}  // namespace penumbra::test
