// Lobe masks: eval / pdf with a mask include exactly those lobes, and sample() restricted to a
// mask only returns lobes of the mask. The distributed (Cook) integrator relies on this.
#include <gtest/gtest.h>

#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

TEST(BsdfLobeMask, EvalIsSumOverDisjointMasks) {
  test::Rng rng(3);
  std::vector<MaterialParams> mats = {
      DiffuseParams{Spectrum(0.5f)},
      ConductorParams{Spectrum(0.9f), 0.3f},
      DielectricParams{1.5f, 0.3f, Spectrum(0.f)},
      PlasticParams{Spectrum(0.3f, 0.6f, 0.2f), 1.5f, 0.f},
      PlasticParams{Spectrum(0.3f, 0.6f, 0.2f), 1.5f, 0.3f},
  };
  for (const auto& p : mats) {
    const Material mat(p);
    for (int i = 0; i < 2000; ++i) {
      const vec3 wi = test::uniform_sphere(rng), wo = test::uniform_sphere(rng);
      const Spectrum all = mat.eval(BsdfContext{kLobeAll}, wi, wo);
      const Spectrum split = mat.eval(BsdfContext{kLobeDiffuse}, wi, wo) +
                             mat.eval(BsdfContext{kLobeNonDiffuse}, wi, wo);
      const Spectrum rt = mat.eval(BsdfContext{kLobeDiffuse | kLobeGlossyReflection}, wi, wo) +
                          mat.eval(BsdfContext{kLobeGlossyTransmission}, wi, wo);
      for (int c = 0; c < 3; ++c) {
        ASSERT_NEAR(all[c], split[c], 1e-5f * all[c] + 1e-7f);
        ASSERT_NEAR(all[c], rt[c], 1e-5f * all[c] + 1e-7f);
      }
      ASSERT_EQ(mat.eval(BsdfContext{0u}, wi, wo), Spectrum(0.f));
      ASSERT_EQ(mat.pdf(BsdfContext{0u}, wi, wo), 0.f);
    }
  }
}

TEST(BsdfLobeMask, PlasticNonDiffuseSamplesOnlyTheCoating) {
  test::Rng rng(5);
  for (float r : {0.f, 0.3f}) {
    const Material mat(PlasticParams{Spectrum(0.8f), 1.5f, r});
    const BsdfContext coat{kLobeNonDiffuse}, base{kLobeDiffuse};
    for (int i = 0; i < 5000; ++i) {
      const vec3 wi = test::spherical(std::acos(rng.next()), 2.f * kPi * rng.next());
      const auto bs = mat.sample(coat, wi, rng.next(), rng.next2());
      if (bs) {
        ASSERT_EQ(bs->lobe & kLobeDiffuse, 0u);
        if (r == 0.f) {
          // The coating is chosen with probability 1: weight = F exactly.
          ASSERT_EQ(bs->pdf, 0.f);
          ASSERT_LE(bs->weight.x, 1.f);
        } else {
          ASSERT_NEAR(bs->pdf, mat.pdf(coat, wi, bs->wo), 1e-3f * bs->pdf);
        }
      }
      const auto bd = mat.sample(base, wi, rng.next(), rng.next2());
      ASSERT_TRUE(bd.has_value());
      ASSERT_EQ(bd->lobe, uint32_t(kLobeDiffuseReflection));
      // Restricted to the base, the pdf is the plain cosine density.
      ASSERT_NEAR(bd->pdf, bd->wo.z * kInvPi, 1e-4f);
      ASSERT_EQ(mat.eval(coat, wi, bd->wo) + mat.eval(base, wi, bd->wo),
                mat.eval(BsdfContext{}, wi, bd->wo));
    }
  }
}

TEST(BsdfLobeMask, LobesMatchModel) {
  EXPECT_EQ(Material(DiffuseParams{}).lobes(), uint32_t(kLobeDiffuseReflection));
  EXPECT_EQ(Material(ConductorParams{Spectrum(1.f), 0.f}).lobes(), uint32_t(kLobeDeltaReflection));
  EXPECT_EQ(Material(ConductorParams{Spectrum(1.f), 1e-3f}).lobes(), uint32_t(kLobeDeltaReflection));
  EXPECT_EQ(Material(ConductorParams{Spectrum(1.f), 0.5f}).lobes(), uint32_t(kLobeGlossyReflection));
  EXPECT_EQ(Material(DielectricParams{1.5f, 0.f, Spectrum(0.f)}).lobes(), uint32_t(kLobeDelta));
  EXPECT_EQ(Material(DielectricParams{1.5f, 0.5f, Spectrum(0.f)}).lobes(), uint32_t(kLobeGlossy));
  EXPECT_EQ(Material(PlasticParams{Spectrum(0.5f), 1.5f, 0.f}).lobes(),
            uint32_t(kLobeDiffuseReflection | kLobeDeltaReflection));
  EXPECT_EQ(Material(PlasticParams{Spectrum(0.5f), 1.5f, 0.5f}).lobes(),
            uint32_t(kLobeDiffuseReflection | kLobeGlossyReflection));
}

}  // namespace
}  // namespace penumbra::test
