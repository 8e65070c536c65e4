// Helmholtz reciprocity f(wi, wo) = f(wo, wi) for reflection, and for refraction the generalised
// reciprocity of radiance BSDFs f(wi, wo) / eta_i^2 = f(wo, wi) / eta_o^2 (Veach 1997 eq. 5.14),
// eta_x being the ior on x's side. f = eval / |cos theta_o|.
#include <gtest/gtest.h>

#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

TEST(BsdfReciprocity, ReflectionAndRefraction) {
  test::Rng rng(13);
  const float ior = 1.5f;
  std::vector<MaterialParams> mats = {
      DiffuseParams{Spectrum(0.5f)},
      ConductorParams{Spectrum(0.9f), 0.05f},
      ConductorParams{Spectrum(0.9f), 0.5f},
      DielectricParams{ior, 0.3f, Spectrum(0.f)},
      DielectricParams{ior, 1.f, Spectrum(0.f)},
      PlasticParams{Spectrum(0.4f), ior, 0.f},
      PlasticParams{Spectrum(0.4f), ior, 0.4f},
  };
  for (const auto& p : mats) {
    const Material mat(p);
    const bool dielectric = std::holds_alternative<DielectricParams>(p);
    int nonzero = 0;
    for (int i = 0; i < 20000; ++i) {
      const vec3 wi = test::uniform_sphere(rng), wo = test::uniform_sphere(rng);
      if (std::abs(wi.z) < 1e-3f || std::abs(wo.z) < 1e-3f) continue;
      const float f_io = mat.eval(BsdfContext{}, wi, wo).x / std::abs(wo.z);
      const float f_oi = mat.eval(BsdfContext{}, wo, wi).x / std::abs(wi.z);
      float lhs = f_io, rhs = f_oi;
      if (dielectric) {
        const float eta_i = wi.z > 0.f ? 1.f : ior, eta_o = wo.z > 0.f ? 1.f : ior;
        lhs /= eta_i * eta_i;
        rhs /= eta_o * eta_o;
      }
      ASSERT_NEAR(lhs, rhs, 2e-3f * std::max(lhs, rhs) + 1e-6f)
          << "material " << p.index() << " wi.z " << wi.z << " wo.z " << wo.z;
      nonzero += lhs > 0.f;
    }
    EXPECT_GT(nonzero, 100);
  }
}

}  // namespace
}  // namespace penumbra::test
