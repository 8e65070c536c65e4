// Normal mapping (SurfaceBsdf::set_mapped_normal, after Mitsuba 3.9's `normalmap` with its
// defaults): a flat map changes nothing; a tilted one evaluates the model in the tilted frame,
// times the Estevez et al. 2019 shadowing term, and only where a direction lies on the same side
// of both normals; a normal facing away from wi is mirrored; sampling agrees with eval and pdf.
#include <gtest/gtest.h>

#include "renderer/materials/coating_tables.h"
#include "renderer/materials/surface_bsdf.h"
#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

// The shadowing term written out from Estevez et al. 2019: G1 of GGX with alpha^2 =
// min(tan^2(theta_n) / 8, 1).
double shadowing(const vec3& n, const vec3& wo) {
  const double tan2_n = (1.0 - double(n.z) * n.z) / (double(n.z) * n.z);
  const double tan2_o = (1.0 - double(wo.z) * wo.z) / (double(wo.z) * wo.z);
  const double alpha2 = std::min(tan2_n / 8.0, 1.0);
  return 2.0 / (1.0 + std::sqrt(1.0 + alpha2 * tan2_o));
}

SurfaceBsdf mapped(const BsdfModel& model, const vec3& n) {
  SurfaceBsdf b(model);
  b.set_mapped_normal(n);
  return b;
}

TEST(NormalMap, FlatMapChangesNothing) {
  const SurfaceBsdf plain(ConductorBsdf(Spectrum(0.9f), 0.4f));
  const SurfaceBsdf flat = mapped(ConductorBsdf(Spectrum(0.9f), 0.4f), vec3(0.f, 0.f, 1.f));
  Rng rng(7);
  for (int i = 0; i < 200; ++i) {
    const vec3 wi = uniform_sphere(rng), wo = uniform_sphere(rng);
    EXPECT_EQ(flat.eval(BsdfContext{}, wi, wo), plain.eval(BsdfContext{}, wi, wo));
    EXPECT_EQ(flat.pdf(BsdfContext{}, wi, wo), plain.pdf(BsdfContext{}, wi, wo));
    const float ul = rng.next();
    const vec2 u = rng.next2();
    const auto a = flat.sample(BsdfContext{}, wi, ul, u),
               b = plain.sample(BsdfContext{}, wi, ul, u);
    ASSERT_EQ(a.has_value(), b.has_value());
    if (a) {
      EXPECT_EQ(a->wo, b->wo);
    }
  }
}

TEST(NormalMap, TiltedDiffuseByHand) {
  const float tilt = deg(30.f);
  const vec3 n(std::sin(tilt), 0.f, std::cos(tilt));
  const SurfaceBsdf b = mapped(DiffuseBsdf(Spectrum(0.6f)), 2.f * n);  // the map need not be unit
  const vec3 wi(0.f, 0.f, 1.f);
  for (float theta : {-80.f, -40.f, 0.f, 20.f, 55.f, 70.f, 85.f}) {
    const vec3 wo = spherical(deg(std::abs(theta)), theta < 0.f ? kPi : 0.f);
    const double cos_n = glm::dot(wo, n);
    const double expected = cos_n > 0.0 ? 0.6 / M_PI * cos_n * shadowing(n, wo) : 0.0;
    EXPECT_NEAR(b.eval(BsdfContext{}, wi, wo).x, expected, 1e-6) << "theta_o " << theta;
  }
  // A direction above the tilted normal's horizon but below the surface's: nothing (it would
  // leak light through the surface).
  const vec3 below = glm::normalize(vec3(1.f, 0.f, -0.2f));
  ASSERT_GT(glm::dot(below, n), 0.f);
  EXPECT_EQ(b.eval(BsdfContext{}, wi, below), Spectrum(0.f));
  EXPECT_EQ(b.pdf(BsdfContext{}, wi, below), 0.f);
}

TEST(NormalMap, NormalFacingAwayFromTheViewerIsMirrored) {
  // Tilted 60 degrees towards +x, seen from far out on -x: wi . n < 0, so the normal used is the
  // mirror image (-x tilt), as Mitsuba's flip_invalid_normals.
  const float tilt = deg(60.f);
  const vec3 n(std::sin(tilt), 0.f, std::cos(tilt)), mirrored(-n.x, -n.y, n.z);
  const SurfaceBsdf b = mapped(DiffuseBsdf(Spectrum(1.f)), n);
  const vec3 wi = spherical(deg(75.f), kPi);
  ASSERT_LT(glm::dot(wi, n), 0.f);
  const vec3 wo = spherical(deg(40.f), kPi);
  const double expected = 1.0 / M_PI * glm::dot(wo, mirrored) * shadowing(mirrored, wo);
  EXPECT_NEAR(b.eval(BsdfContext{}, wi, wo).x, expected, 1e-6);
}

TEST(NormalMap, BackSideOfATwoSidedModelMirrorsTheMap) {
  const vec3 n = glm::normalize(vec3(0.3f, -0.2f, 0.9f));
  const SurfaceBsdf b = mapped(DiffuseBsdf(Spectrum(0.5f)), n);
  const vec3 wi = glm::normalize(vec3(0.1f, 0.4f, 0.7f)),
             wo = glm::normalize(vec3(-0.5f, 0.2f, 0.6f));
  const auto flip = [](const vec3& v) { return vec3(v.x, v.y, -v.z); };
  EXPECT_EQ(b.eval(BsdfContext{}, flip(wi), flip(wo)), b.eval(BsdfContext{}, wi, wo));
}

// sample() agrees with eval() / pdf() for every model under a strong perturbation.
TEST(NormalMap, SampleWeightIsEvalOverPdf) {
  CoatingTableCache coatings;
  const PlasticParams plastic{Spectrum(0.3f, 0.5f, 0.7f), 1.5f, 0.3f};
  const BsdfModel models[] = {DiffuseBsdf(Spectrum(0.7f)), ConductorBsdf(Spectrum(0.9f), 0.3f),
                              PlasticBsdf(plastic, PlasticBsdf::tables_for(plastic, coatings)),
                              DielectricBsdf(1.5f, 0.4f, Spectrum(0.f))};
  const vec3 n = glm::normalize(vec3(0.5f, 0.3f, 0.8f));
  Rng rng(11);
  for (const BsdfModel& model : models) {
    const SurfaceBsdf b = mapped(model, n);
    int checked = 0;
    for (int i = 0; i < 4000; ++i) {
      const vec3 wi = uniform_sphere(rng);
      const auto bs = b.sample(BsdfContext{}, wi, rng.next(), rng.next2());
      if (!bs || bs->pdf == 0.f) continue;
      const float pdf = b.pdf(BsdfContext{}, wi, bs->wo);
      const Spectrum f = b.eval(BsdfContext{}, wi, bs->wo);
      ASSERT_NEAR(pdf, bs->pdf, 1e-3f * bs->pdf + 1e-5f) << "model " << model.index();
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(f[c] / pdf, bs->weight[c], 2e-3f * bs->weight[c] + 1e-5f)
            << "model " << model.index();
      ++checked;
    }
    EXPECT_GT(checked, 1000) << "model " << model.index();
  }
}

// Normal mapping only removes energy (the shadowing term, directions on the wrong side).
TEST(NormalMap, WhiteDiffuseNeverGainsEnergy) {
  const SurfaceBsdf b = mapped(DiffuseBsdf(Spectrum(1.f)), glm::normalize(vec3(0.4f, 0.f, 0.9f)));
  Rng rng(3);
  for (float theta : {0.f, 30.f, 60.f, 85.f}) {
    const vec3 wi = spherical(deg(theta), 0.5f);
    double sum = 0.0;
    const int n = 100000;
    for (int i = 0; i < n; ++i)
      if (const auto bs = b.sample(BsdfContext{}, wi, rng.next(), rng.next2())) sum += bs->weight.x;
    EXPECT_LE(sum / n, 1.0 + 3e-3) << "theta_i " << theta;
  }
}

class NormalMapChi2 : public ::testing::TestWithParam<int> {};

TEST_P(NormalMapChi2, SampleMatchesPdf) {
  CoatingTableCache coatings;
  const PlasticParams plastic{Spectrum(0.4f), 1.5f, 0.2f};
  const BsdfModel models[] = {DiffuseBsdf(Spectrum(0.7f)), ConductorBsdf(Spectrum(0.9f), 0.3f),
                              PlasticBsdf(plastic, PlasticBsdf::tables_for(plastic, coatings))};
  const int model = GetParam() / 2;
  const vec3 wi = spherical(deg(GetParam() % 2 ? 70.f : 20.f), deg(200.f));
  const SurfaceBsdf b = mapped(models[model], glm::normalize(vec3(0.35f, -0.25f, 0.9f)));
  Chi2Config cfg;
  cfg.num_tests = 6;
  cfg.seed = 0x51ed2701ull + GetParam();
  const auto res = chi2_test(b, BsdfContext{}, wi, cfg);
  EXPECT_TRUE(res.pass) << "model " << model << ": " << res.message;
}

INSTANTIATE_TEST_SUITE_P(Models, NormalMapChi2, ::testing::Range(0, 6));

}  // namespace
}  // namespace penumbra::test
