// sample() agrees with eval() and pdf(): weight == eval / pdf and pdf == pdf(wo) for non-delta
// samples; never NaN/Inf; extreme roughness stays finite.
#include <gtest/gtest.h>

#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

std::vector<MaterialParams> all_materials() {
  std::vector<MaterialParams> m;
  m.push_back(DiffuseParams{Spectrum(0.2f, 0.5f, 0.9f)});
  for (float r : {0.f, 1e-4f, 0.01f, 0.05f, 0.3f, 1.f}) {
    m.push_back(ConductorParams{Spectrum(1.f, 0.78f, 0.34f), r});
    m.push_back(DielectricParams{1.5f, r, Spectrum(0.f)});
    m.push_back(PlasticParams{Spectrum(0.1f, 0.2f, 0.6f), 1.5f, r});
    m.push_back(MetallicRoughnessParams{Spectrum(0.9f, 0.6f, 0.1f), 0.5f, r});
  }
  m.push_back(DielectricParams{1.f, 0.3f, Spectrum(0.f)});
  return m;
}

float roughness_of(const MaterialParams& p) {
  return std::visit(
      [](const auto& m) {
        if constexpr (requires { m.roughness; }) return m.roughness;
        else return 1.f;
      },
      p);
}

TEST(BsdfConsistency, SampleWeightEqualsEvalOverPdf) {
  test::Rng rng(7);
  const uint32_t masks[] = {kLobeAll, kLobeDiffuse, kLobeNonDiffuse, kLobeGlossyReflection,
                            kLobeGlossyTransmission};
  for (const auto& params : all_materials()) {
    const Material mat(params);
    for (uint32_t mask : masks) {
      const BsdfContext ctx{mask};
      int checked = 0;
      for (int i = 0; i < 4000; ++i) {
        const vec3 wi = test::uniform_sphere(rng);
        const auto bs = mat.sample(ctx, wi, rng.next(), rng.next2());
        if (!bs) continue;
        ASSERT_TRUE(is_finite(bs->weight) && std::isfinite(bs->pdf));
        ASSERT_NEAR(glm::length(bs->wo), 1.f, 1e-3f);
        ASSERT_NE(bs->lobe & mask, 0u) << "sampled a lobe outside the mask";
        ASSERT_NE(bs->lobe & mat.lobes(), 0u);
        if (bs->pdf == 0.f) {
          ASSERT_NE(bs->lobe & kLobeDelta, 0u);
          continue;
        }
        // pdf() recomputes the half vector from wi + wo, |wi + wo| ~ 2 |wi.z|: in float it is off by
        // ~1e-7 / |wi.z| rad, which matters relative to the lobe width alpha at grazing angles.
        const float alpha = std::max(1e-4f, sqr(roughness_of(params)));
        const float rel = 2e-3f + 4e-7f / (std::abs(wi.z) * alpha);
        const Spectrum f = mat.eval(ctx, wi, bs->wo);
        const float pdf = mat.pdf(ctx, wi, bs->wo);
        ASSERT_NEAR(pdf, bs->pdf, rel * bs->pdf + 1e-6f) << "material " << params.index() << " r " << (std::holds_alternative<ConductorParams>(params) ? std::get<ConductorParams>(params).roughness : std::holds_alternative<DielectricParams>(params) ? std::get<DielectricParams>(params).roughness : -1.f) << " mask " << mask << " wi.z " << wi.z << " wo.z " << bs->wo.z;
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(bs->weight[c], f[c] / bs->pdf, rel * bs->weight[c] + 1e-5f)
              << "mask " << mask << " wi.z " << wi.z << " wo.z " << bs->wo.z;
        ++checked;
      }
      (void)checked;
    }
  }
}

TEST(BsdfConsistency, EvalAndPdfAreFiniteAndNonNegative) {
  test::Rng rng(11);
  for (const auto& params : all_materials()) {
    const Material mat(params);
    for (int i = 0; i < 20000; ++i) {
      vec3 wi = test::uniform_sphere(rng), wo = test::uniform_sphere(rng);
      if (i % 4 == 0) wo = vec3(-wi.x, -wi.y, wi.z);  // exact mirror: half vector on the pole
      if (i % 4 == 1) wo = -wi;                       // straight through
      if (i % 8 == 2) wi.z = 0.f, wi = glm::normalize(wi + vec3(1e-7f));  // grazing
      const Spectrum f = mat.eval(BsdfContext{}, wi, wo);
      const float p = mat.pdf(BsdfContext{}, wi, wo);
      ASSERT_TRUE(is_finite(f) && std::isfinite(p));
      ASSERT_GE(std::min(f.x, std::min(f.y, f.z)), 0.f);
      ASSERT_GE(p, 0.f);
    }
  }
}

TEST(BsdfConsistency, IndexMatchedDielectricIsInvisible) {
  for (float r : {0.f, 0.3f, 1.f}) {
    const Material mat(DielectricParams{1.f, r, Spectrum(0.f)});
    EXPECT_EQ(mat.lobes(), uint32_t(kLobeDeltaTransmission));
    for (float t : {10.f, 80.f, 120.f}) {
      const vec3 wi = test::spherical(test::deg(t), 1.f);
      const auto bs = mat.sample(BsdfContext{}, wi, 0.3f, vec2(0.4f, 0.6f));
      ASSERT_TRUE(bs.has_value());
      EXPECT_EQ(bs->lobe, uint32_t(kLobeDeltaTransmission));
      EXPECT_NEAR(glm::length(bs->wo + wi), 0.f, 1e-6f);
      EXPECT_EQ(bs->weight, Spectrum(1.f));
      EXPECT_EQ(bs->eta, 1.f);
    }
  }
}

TEST(BsdfConsistency, SmoothDielectricDirections) {
  const Material mat(DielectricParams{1.5f, 0.f, Spectrum(0.f)});
  const vec3 wi = test::spherical(test::deg(40.f), 0.5f);
  const auto t = mat.sample(BsdfContext{kLobeDeltaTransmission}, wi, 0.5f, vec2(0.5f));
  ASSERT_TRUE(t.has_value());
  // Snell: sin_t = sin_i / 1.5, wo below the surface, opposite azimuth.
  EXPECT_NEAR(std::sqrt(1.f - t->wo.z * t->wo.z), std::sin(test::deg(40.f)) / 1.5f, 1e-5f);
  EXPECT_LT(t->wo.z, 0.f);
  EXPECT_FLOAT_EQ(t->eta, 1.5f);
  // Beyond the critical angle from inside only reflection exists.
  const vec3 inside = test::spherical(test::deg(180.f - 50.f), 0.5f);
  EXPECT_FALSE(mat.sample(BsdfContext{kLobeDeltaTransmission}, inside, 0.5f, vec2(0.5f)));
  const auto r = mat.sample(BsdfContext{}, inside, 0.999f, vec2(0.5f));
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->lobe, uint32_t(kLobeDeltaReflection));
  EXPECT_FLOAT_EQ(r->weight.x, 1.f);
}

TEST(BsdfConsistency, AbsorptionOnlyForDielectrics) {
  EXPECT_EQ(Material(DielectricParams{1.5f, 0.f, Spectrum(0.1f, 0.2f, 0.3f)}).absorption(),
            Spectrum(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(Material(DiffuseParams{}).absorption(), Spectrum(0.f));
  EXPECT_TRUE(Material(DielectricParams{}).has_transmission());
  EXPECT_FALSE(Material(PlasticParams{}).has_transmission());
}

}  // namespace
}  // namespace penumbra::test
