// eval_pdf (one call for a BSDF's value and pdf, as Mitsuba 3's BSDF::eval_pdf) equals eval and
// pdf to the bit, for every model on its own and through SurfaceBsdf (back sides of two-sided
// models, normal maps), over every lobe mask and many direction pairs: random pairs on the
// sphere, pairs from the model's own sampling (inside narrow lobes), mirror and straight-through
// pairs, grazing and exactly tangent directions. Next-event estimation relies on it: the images
// must not change when it asks for both at once.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "renderer/materials/coating_tables.h"
#include "renderer/materials/surface_bsdf.h"
#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {
namespace {

bool same_bits(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }

std::string describe(float x) {
  std::ostringstream s;
  s << std::hexfloat << x;
  return s.str();
}

std::string describe(const vec3& v) {
  return "(" + describe(v.x) + ", " + describe(v.y) + ", " + describe(v.z) + ")";
}

::testing::AssertionResult identical(const BsdfEvalPdf& both, const Spectrum& f, float pdf) {
  bool same = same_bits(both.pdf, pdf);
  for (int c = 0; c < 3; ++c) same = same && same_bits(both.f[c], f[c]);
  if (same) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "eval_pdf gives f " << describe(both.f) << ", pdf "
                                       << describe(both.pdf) << "; eval " << describe(f)
                                       << ", pdf " << describe(pdf);
}

// The comparison sees a difference of one ulp in any of the four numbers.
TEST(BsdfEvalPdf, ComparisonSeesOneUlp) {
  const BsdfEvalPdf e{Spectrum(0.25f, 0.5f, 0.75f), 1.5f};
  EXPECT_TRUE(identical(e, e.f, e.pdf));
  EXPECT_FALSE(identical(e, e.f, std::nextafter(e.pdf, 2.f)));
  for (int c = 0; c < 3; ++c) {
    Spectrum f = e.f;
    f[c] = std::nextafter(f[c], 1.f);
    EXPECT_FALSE(identical(e, f, e.pdf));
  }
  // The sign of a zero counts as well.
  EXPECT_FALSE(identical(BsdfEvalPdf{Spectrum(0.f), 0.f}, Spectrum(0.f), -0.f));
}

struct Case {
  std::string name;
  BsdfModel model;
  // Whether eval and pdf can be non-zero anywhere: not for the Dirac-only models, nor for a
  // smooth pure metal, whose diffuse lobe is empty (no base, no multiple scattering).
  bool has_values = true;
};

// Every model, smooth and rough, with the parameters that select different code paths.
std::vector<Case> all_models(CoatingTableCache& coatings) {
  std::vector<Case> cases;
  cases.push_back({"diffuse", DiffuseBsdf(Spectrum(0.2f, 0.5f, 0.9f))});
  for (float r : {0.f, 0.01f, 0.05f, 0.3f, 0.7f, 1.f}) {
    const std::string rs = " r=" + std::to_string(r);
    const bool smooth = roughness_to_alpha(r) < kMinMicrofacetAlpha;
    cases.push_back({"conductor" + rs, ConductorBsdf(Spectrum(1.f, 0.78f, 0.34f), r), !smooth});
    for (float ior : {1.5f, 1.33f, 0.7f, 2.4f})
      cases.push_back({"dielectric ior=" + std::to_string(ior) + rs,
                       DielectricBsdf(ior, r, Spectrum(0.f)), !smooth});
    for (float ior : {1.5f, 1.9f}) {
      const PlasticParams p{Spectrum(0.1f, 0.2f, 0.6f), ior, r};
      cases.push_back({"plastic ior=" + std::to_string(ior) + rs,
                       PlasticBsdf(p, PlasticBsdf::tables_for(p, coatings))});
    }
    for (float metallic : {0.f, 0.5f, 1.f})
      cases.push_back({"metallic_roughness m=" + std::to_string(metallic) + rs,
                       MetallicRoughnessBsdf(Spectrum(0.9f, 0.6f, 0.1f), metallic, r),
                       !(smooth && metallic == 1.f)});
  }
  cases.push_back({"dielectric index-matched", DielectricBsdf(1.f, 0.3f, Spectrum(0.f)), false});
  // A textured base, as Material::bsdf_at builds it per hit.
  const PlasticParams p{Spectrum(0.5f), 1.5f, 0.3f};
  cases.push_back({"plastic with_color",
                   PlasticBsdf(p, PlasticBsdf::tables_for(p, coatings))
                       .with_color(Spectrum(0.9f, 0.05f, 0.3f))});
  return cases;
}

// Direction pairs that reach every branch: random, sampled by the BSDF itself (so narrow lobes
// give non-zero values), mirror and straight-through pairs, grazing and tangent directions,
// half vectors that vanish.
template <typename Bsdf>
std::vector<std::pair<vec3, vec3>> direction_pairs(const Bsdf& bsdf, Rng& rng, int n) {
  std::vector<std::pair<vec3, vec3>> pairs;
  for (int i = 0; i < n; ++i) {
    vec3 wi = uniform_sphere(rng);
    if (i % 16 == 3) wi = glm::normalize(vec3(wi.x, wi.y, 1e-4f * wi.z));  // grazing
    if (i % 32 == 5) wi = glm::normalize(vec3(wi.x, wi.y, 0.f));           // tangent
    vec3 wo;
    switch (i % 8) {
      case 0:
      case 1:
      case 2: {
        const auto bs = bsdf.sample(BsdfContext{}, wi, rng.next(), rng.next2());
        wo = bs ? bs->wo : uniform_sphere(rng);
        break;
      }
      case 3: wo = vec3(-wi.x, -wi.y, wi.z); break;  // mirror: half vector on the pole
      case 4: wo = -wi; break;                       // straight through
      case 5: wo = wi; break;                        // back along the incident direction
      case 6: wo = glm::normalize(vec3(-wi.x, -wi.y, wi.z) + 0.01f * uniform_sphere(rng)); break;
      default: wo = uniform_sphere(rng); break;
    }
    if (i % 64 == 7) wo = glm::normalize(vec3(wo.x, wo.y, 0.f));  // tangent
    pairs.emplace_back(wi, wo);
  }
  return pairs;
}

struct Counts {
  int f_nonzero = 0, pdf_nonzero = 0;
};

// Every lobe mask, every pair: eval_pdf against eval and pdf.
template <typename Bsdf>
void expect_identical(const Bsdf& bsdf, const std::vector<std::pair<vec3, vec3>>& pairs,
                      const std::string& name, Counts* counts) {
  for (uint32_t mask = 0; mask <= kLobeAll; ++mask) {
    const BsdfContext ctx{mask};
    for (const auto& [wi, wo] : pairs) {
      const BsdfEvalPdf both = bsdf.eval_pdf(ctx, wi, wo);
      const Spectrum f = bsdf.eval(ctx, wi, wo);
      const float pdf = bsdf.pdf(ctx, wi, wo);
      ASSERT_TRUE(identical(both, f, pdf))
          << name << ", mask " << mask << ", wi " << describe(wi) << ", wo " << describe(wo);
      if (!is_black(f)) ++counts->f_nonzero;
      if (pdf != 0.f) ++counts->pdf_nonzero;
    }
  }
}

TEST(BsdfEvalPdf, EveryModelEqualsEvalAndPdfExactly) {
  CoatingTableCache coatings;
  Rng rng(2024);
  for (const Case& c : all_models(coatings)) {
    std::visit(
        [&](const auto& model) {
          const auto pairs = direction_pairs(model, rng, 1500);
          Counts counts;
          expect_identical(model, pairs, c.name, &counts);
          if (c.has_values) {
            EXPECT_GT(counts.f_nonzero, 1000) << c.name;
            EXPECT_GT(counts.pdf_nonzero, 1000) << c.name;
          }
        },
        c.model);
    if (HasFatalFailure()) return;
  }
}

// SurfaceBsdf adds the two-sided mirroring (wi on the back of an opaque model) and the
// non-finite guards; the random pairs put wi on both sides.
TEST(BsdfEvalPdf, SurfaceBsdfEqualsEvalAndPdfExactly) {
  CoatingTableCache coatings;
  Rng rng(77);
  for (const Case& c : all_models(coatings)) {
    const SurfaceBsdf bsdf(c.model);
    const auto pairs = direction_pairs(bsdf, rng, 1500);
    int back = 0;
    for (const auto& pair : pairs) back += pair.first.z < 0.f;
    EXPECT_GT(back, 400) << c.name;
    Counts counts;
    expect_identical(bsdf, pairs, c.name, &counts);
    if (HasFatalFailure()) return;
    if (c.has_values) {
      EXPECT_GT(counts.f_nonzero, 1000) << c.name;
      EXPECT_GT(counts.pdf_nonzero, 1000) << c.name;
    }
  }
}

// The normal-mapped path: the perturbed frame, the same-side test of both normals, a normal
// facing away from wi mirrored, the shadowing term on the value only; for tilted, steep,
// non-unit and degenerate (zero) map normals, from both sides.
TEST(BsdfEvalPdf, NormalMappedSurfaceBsdfEqualsEvalAndPdfExactly) {
  CoatingTableCache coatings;
  Rng rng(5);
  const vec3 normals[] = {glm::normalize(vec3(0.5f, 0.3f, 0.8f)),
                          glm::normalize(vec3(-0.9f, 0.2f, 0.3f)),
                          vec3(0.f, 0.f, 1.f),
                          2.f * glm::normalize(vec3(0.1f, -0.4f, 0.9f)),
                          vec3(1.f, 0.f, 0.f),
                          vec3(0.f)};
  for (const Case& c : all_models(coatings)) {
    for (const vec3& n : normals) {
      SurfaceBsdf bsdf(c.model);
      bsdf.set_mapped_normal(n);
      const auto pairs = direction_pairs(bsdf, rng, 400);
      Counts counts;
      expect_identical(bsdf, pairs, c.name + ", map normal " + describe(n), &counts);
      if (HasFatalFailure()) return;
      if (c.has_values && n != vec3(1.f, 0.f, 0.f)) {
        EXPECT_GT(counts.f_nonzero, 100) << c.name << " " << describe(n);
        EXPECT_GT(counts.pdf_nonzero, 100) << c.name << " " << describe(n);
      }
    }
  }
}

// Material, which the tests of the other suites use, answers the same.
TEST(BsdfEvalPdf, MaterialEqualsEvalAndPdfExactly) {
  Rng rng(9);
  const MaterialParams params[] = {DiffuseParams{Spectrum(0.4f)},
                                   ConductorParams{Spectrum(0.9f), 0.2f},
                                   DielectricParams{1.5f, 0.2f, Spectrum(0.f)},
                                   PlasticParams{Spectrum(0.3f, 0.6f, 0.2f), 1.5f, 0.2f},
                                   MetallicRoughnessParams{Spectrum(0.8f), 0.3f, 0.4f}};
  for (const MaterialParams& p : params) {
    const Material mat(p);
    Counts counts;
    expect_identical(mat, direction_pairs(mat, rng, 500), "material " + std::to_string(p.index()),
                     &counts);
    if (HasFatalFailure()) return;
    EXPECT_GT(counts.pdf_nonzero, 100);
  }
}

}  // namespace
}  // namespace penumbra::test
