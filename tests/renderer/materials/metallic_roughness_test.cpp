// The glTF metallic-roughness BSDF (renderer/materials/metallic_roughness.h): the white furnace
// (albedo exactly 1 for a white base colour at every metallic, roughness and angle; at most 1
// for any colour), and its values against an independent double-precision evaluation of the
// model as docs/gltf.md writes it down (own D, G1 and Fresnel formulas, albedo tables by
// brute-force quadrature over the outgoing hemisphere instead of visible-normal tables).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "renderer/materials/material.h"
#include "renderer/materials/metallic_roughness.h"
#include "renderer/materials/microfacet_albedo.h"
#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// ---- the independent evaluation ---------------------------------------------------------------

struct Reference {
  double alpha;
  explicit Reference(double roughness) : alpha(roughness * roughness) {}

  // GGX (Trowbridge-Reitz) in its cos form, Walter et al. 2007 eq. 33.
  double d(double cos_h) const {
    const double a2 = alpha * alpha;
    const double t = cos_h * cos_h * (a2 - 1.0) + 1.0;
    return a2 / (kPiD * t * t);
  }
  // Smith G1 for GGX, the form 2 cos / (cos + sqrt(a^2 + (1 - a^2) cos^2)) (Walter et al. eq. 34
  // rewritten).
  double g1(double c) const {
    const double a2 = alpha * alpha;
    return 2.0 * c / (c + std::sqrt(a2 + (1.0 - a2) * c * c));
  }
  static double schlick(double f0, double c) { return f0 + (1.0 - f0) * std::pow(1.0 - c, 5.0); }

  // f cos_o of the Fresnel-free specular lobe.
  double spec(const glm::dvec3& wi, const glm::dvec3& wo) const {
    const glm::dvec3 h = glm::normalize(wi + wo);
    return d(h.z) * g1(wi.z) * g1(wo.z) / (4.0 * wi.z);
  }

  // E(mu) and its Schlick part E5(mu), by the midpoint rule over (cos theta_o, phi_o): 2048 x 256
  // cells; the lobes tested here (roughness >= 0.3) are wide enough for it.
  std::pair<double, double> albedo(double mu) const {
    const glm::dvec3 wi(std::sqrt(1.0 - mu * mu), 0.0, mu);
    const int nc = 2048, np = 256;
    double e = 0, e5 = 0;
    for (int a = 0; a < nc; ++a) {
      const double c = (a + 0.5) / nc;
      const double s = std::sqrt(1.0 - c * c);
      for (int b = 0; b < np; ++b) {
        const double phi = kPiD * (b + 0.5) / np;  // symmetric in phi: half the circle, twice
        const glm::dvec3 wo(s * std::cos(phi), s * std::sin(phi), c);
        const double v = spec(wi, wo) * 2.0 * kPiD / np / nc;
        e += v;
        e5 += v * std::pow(1.0 - glm::dot(wi, glm::normalize(wi + wo)), 5.0);
      }
    }
    return {e, e5};
  }
};

// f cos_o of the whole model (docs/gltf.md) from the reference pieces.
glm::dvec3 reference_eval(const Reference& ref, const glm::dvec3& base, double metallic,
                          const glm::dvec3& wi, const glm::dvec3& wo, double e_avg, double e5_avg) {
  const glm::dvec3 h = glm::normalize(wi + wo);
  const double c = glm::dot(wi, h);
  const double s = ref.spec(wi, wo);
  glm::dvec3 f(0.0);
  for (int k = 0; k < 3; ++k)
    f[k] = ((1 - metallic) * Reference::schlick(0.04, c) + metallic * Reference::schlick(base[k], c)) * s;
  const auto [ei, e5i] = ref.albedo(wi.z);
  const auto [eo, e5o] = ref.albedo(wo.z);
  const double efi = 0.04 * (ei - e5i) + e5i, efo = 0.04 * (eo - e5o) + e5o;
  const double ef_avg = 0.04 * (e_avg - e5_avg) + e5_avg;
  for (int k = 0; k < 3; ++k) {
    const double f_avg = base[k] + (1 - base[k]) / 21.0;
    const double f_ms = f_avg * f_avg * e_avg / (1 - f_avg * (1 - e_avg));
    f[k] += (1 - metallic) * base[k] * (1 - efi) * (1 - efo) / (kPiD * (1 - ef_avg)) * wo.z;
    f[k] += metallic * f_ms * (1 - ei) * (1 - eo) / (kPiD * (1 - e_avg)) * wo.z;
  }
  return f;
}

TEST(MetallicRoughness, MatchesAnIndependentEvaluationOfTheModel) {
  Rng rng(11);
  for (double roughness : {0.3, 0.6, 1.0}) {
    const Reference ref(roughness);
    // E_avg and E5_avg: 2 \int E mu dmu by Gauss-Legendre-free Simpson over 33 nodes.
    double e_avg = 0, e5_avg = 0;
    const int n = 32;
    for (int i = 0; i <= n; ++i) {
      const double mu = std::max(double(i) / n, 1e-4);
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      const auto [e, e5] = ref.albedo(mu);
      e_avg += w * e * mu;
      e5_avg += w * e5 * mu;
    }
    e_avg *= 2.0 / (3.0 * n);
    e5_avg *= 2.0 / (3.0 * n);
    for (double metallic : {0.0, 0.4, 1.0}) {
      const glm::dvec3 base(0.9, 0.55, 0.2);
      const MetallicRoughnessBsdf bsdf{Spectrum(base), float(metallic), float(roughness)};
      for (int k = 0; k < 6; ++k) {
        const vec3 wi = glm::normalize(vec3(rng.next() - 0.5f, rng.next() - 0.5f, 0.15f + rng.next()));
        const vec3 wo = glm::normalize(vec3(rng.next() - 0.5f, rng.next() - 0.5f, 0.15f + rng.next()));
        const Spectrum ours = bsdf.eval(BsdfContext{}, wi, wo);
        const glm::dvec3 expected =
            reference_eval(ref, base, metallic, glm::dvec3(wi), glm::dvec3(wo), e_avg, e5_avg);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(ours[c], expected[c], 0.01 * expected[c] + 2e-4)
              << "roughness " << roughness << " metallic " << metallic << " channel " << c;
      }
    }
  }
}

// ---- the white furnace ---------------------------------------------------------------------

// Directional albedo by sampling: the mean sample weight (delta lobes included).
Spectrum sampled_albedo(const Material& m, const vec3& wi, int n) {
  Rng rng(5);
  glm::dvec3 sum(0.0);
  for (int i = 0; i < n; ++i) {
    const auto bs = m.sample(BsdfContext{}, wi, rng.next(), rng.next2());
    if (bs) sum += glm::dvec3(bs->weight);
  }
  return Spectrum(sum / double(n));
}

TEST(MetallicRoughness, WhiteFurnaceReflectsEverythingAtEveryAngle) {
  for (float metallic : {0.f, 0.3f, 1.f})
    for (float roughness : {0.f, 0.1f, 0.4f, 0.7f, 1.f})
      for (float theta : {0.f, 40.f, 75.f, 87.f}) {
        const Material m(MetallicRoughnessParams{Spectrum(1.f), metallic, roughness});
        const float t = theta * kPi / 180.f;
        const vec3 wi(std::sin(t), 0.f, std::cos(t));
        const Spectrum a = sampled_albedo(m, wi, 200000);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(a[c], 1.f, 6e-3f) << "metallic " << metallic << " roughness " << roughness
                                         << " theta " << theta;
      }
}

TEST(MetallicRoughness, ColouredFurnaceNeverGains) {
  for (float metallic : {0.f, 0.5f, 1.f})
    for (float roughness : {0.f, 0.2f, 0.5f, 1.f})
      for (float theta : {0.f, 60.f, 85.f}) {
        const Material m(MetallicRoughnessParams{Spectrum(0.95f, 0.6f, 0.05f), metallic, roughness});
        const float t = theta * kPi / 180.f;
        const vec3 wi(std::sin(t), 0.f, std::cos(t));
        const Spectrum a = sampled_albedo(m, wi, 100000);
        for (int c = 0; c < 3; ++c) EXPECT_LE(a[c], 1.f + 5e-3f);
        EXPECT_GT(a[0], a[2]);  // the colour shows
      }
}

TEST(MetallicRoughness, AlbedoTableAgreesWithItsAverage) {
  // 2 \int E mu dmu of the interpolated table, by fine quadrature, equals the stored average:
  // what makes the compensation terms conserve energy exactly.
  for (float r : {0.05f, 0.33f, 0.8f}) {
    double e = 0, e5 = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const float mu = (float(i) + 0.5f) / float(n);
      const MicrofacetAlbedo a = ggx_albedo(mu, r);
      e += 2.0 * a.e * mu / n;
      e5 += 2.0 * a.e5 * mu / n;
    }
    EXPECT_NEAR(e, ggx_albedo_average(r).e, 1e-4);
    EXPECT_NEAR(e5, ggx_albedo_average(r).e5, 1e-4);
  }
  // The smooth limit is exact and single scattering loses energy as roughness grows.
  EXPECT_FLOAT_EQ(ggx_albedo(0.5f, 0.f).e, 1.f);
  EXPECT_LT(ggx_albedo_average(1.f).e, ggx_albedo_average(0.5f).e);
  EXPECT_LT(ggx_albedo_average(0.5f).e, 1.f);
}

// The shipped table (ggx_albedo_table.inc) is what the quadrature gives today: a change to the
// quadrature, the resolution or the microfacet model without running
// tools/tables/generate_ggx_albedo_table fails here. Every row, compared to float rounding (the
// quadrature's cos and sin come from libm, whose last bits may differ between versions).
TEST(MetallicRoughness, ShippedAlbedoTableIsTheQuadrature) {
  constexpr int kN = kAlbedoTableRes;
  const float* table = ggx_albedo_table();
  for (int j = 0; j < kN; ++j) {
    SCOPED_TRACE("roughness node " + std::to_string(j));
    const MicrofacetAlbedoRow row = ggx_albedo_row_by_quadrature(j);
    const float r = float(j) / float(kN - 1);
    for (int i = 0; i < kN; ++i) {
      EXPECT_NEAR(table[size_t(2 * (j * kN + i))], row.albedo[i].e, 2e-7f) << "cos node " << i;
      EXPECT_NEAR(table[size_t(2 * (j * kN + i) + 1)], row.albedo[i].e5, 2e-7f) << "cos node " << i;
      // A lookup at a node is the node's value.
      const MicrofacetAlbedo at = ggx_albedo(float(i) / float(kN - 1), r);
      EXPECT_NEAR(at.e, row.albedo[i].e, 2e-7f);
    }
    EXPECT_NEAR(ggx_albedo_average(r).e, row.average.e, 2e-7f);
    EXPECT_NEAR(ggx_albedo_average(r).e5, row.average.e5, 2e-7f);
    EXPECT_GT(row.albedo[kN / 2].e, 0.f);
  }
}

}  // namespace
}  // namespace penumbra::test
