// Chi-square goodness-of-fit of every material's sample() against its pdf(), over roughnesses,
// incident angles up to grazing, both sides of dielectrics (so total internal reflection is
// exercised) and the lobe masks the distributed integrator uses.
#include <gtest/gtest.h>

#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

using test::Chi2Config;
using test::deg;

struct Chi2Case {
  std::string name;
  MaterialParams params;
  uint32_t lobes;
  float theta_deg;  // > 90 means wi below the surface (inside for a dielectric)
};

std::vector<Chi2Case> chi2_cases() {
  std::vector<Chi2Case> cases;
  const float rough[] = {0.05f, 0.3f, 1.f};
  for (float t : {30.f, 89.f, 150.f})
    cases.push_back({"diffuse", DiffuseParams{Spectrum(0.7f)}, kLobeAll, t});
  for (float r : rough)
    for (float t : {0.f, 45.f, 85.f, 89.f})
      cases.push_back({"conductor", ConductorParams{Spectrum(0.9f), r}, kLobeAll, t});
  for (float r : rough)
    for (float t : {10.f, 60.f, 88.f, 170.f, 120.f, 95.f})
      cases.push_back({"dielectric", DielectricParams{1.5f, r, Spectrum(0.f)}, kLobeAll, t});
  // Masked dielectric lobes (the integrator samples them separately).
  cases.push_back({"dielectric", DielectricParams{1.5f, 0.3f, Spectrum(0.f)},
                   kLobeGlossyReflection, 40.f});
  cases.push_back({"dielectric", DielectricParams{1.33f, 0.3f, Spectrum(0.f)},
                   kLobeGlossyTransmission, 130.f});
  for (float r : {0.f, 0.05f, 0.3f, 1.f})
    for (float t : {20.f, 70.f, 87.f})
      cases.push_back({"plastic", PlasticParams{Spectrum(0.3f, 0.5f, 0.8f), 1.5f, r}, kLobeAll, t});
  for (float m : {0.f, 0.5f, 1.f})
    for (float r : {0.f, 0.05f, 0.4f, 1.f})
      for (float t : {15.f, 70.f, 88.f})
        cases.push_back({"metallic_roughness",
                         MetallicRoughnessParams{Spectrum(0.9f, 0.5f, 0.2f), m, r}, kLobeAll, t});
  cases.push_back({"metallic_roughness", MetallicRoughnessParams{Spectrum(0.8f), 0.3f, 0.3f},
                   kLobeDiffuse, 40.f});
  cases.push_back({"metallic_roughness", MetallicRoughnessParams{Spectrum(0.8f), 0.3f, 0.3f},
                   kLobeNonDiffuse, 40.f});
  for (float r : {0.f, 0.3f}) {
    cases.push_back({"plastic", PlasticParams{Spectrum(0.5f), 1.5f, r}, kLobeDiffuse, 50.f});
    cases.push_back({"plastic", PlasticParams{Spectrum(0.5f), 1.5f, r}, kLobeNonDiffuse, 50.f});
  }
  return cases;
}

class BsdfChi2Test : public ::testing::TestWithParam<int> {};

TEST_P(BsdfChi2Test, SampleMatchesPdf) {
  static const std::vector<Chi2Case> cases = chi2_cases();
  const Chi2Case& c = cases[GetParam()];
  const Material mat(c.params);
  // Smooth conductors and dielectrics have only Dirac lobes: nothing to histogram.
  if ((mat.lobes() & ~kLobeDelta) == 0) GTEST_SKIP();
  Chi2Config cfg;
  cfg.num_tests = int(cases.size());
  cfg.seed = 0x9e3779b97f4a7c15ull + GetParam();
  const vec3 wi = test::spherical(deg(c.theta_deg), deg(23.f));
  const auto res = test::chi2_test(mat, BsdfContext{c.lobes}, wi, cfg);
  EXPECT_TRUE(res.pass) << c.name << " theta_i = " << c.theta_deg << " lobes = " << c.lobes
                        << ": " << res.message;
}

INSTANTIATE_TEST_SUITE_P(BsdfAllMaterials, BsdfChi2Test,
                         ::testing::Range(0, int(chi2_cases().size())));

}  // namespace
}  // namespace penumbra::test
