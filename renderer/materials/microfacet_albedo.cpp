#include "renderer/materials/microfacet_albedo.h"

#include <array>
#include <vector>

#include "renderer/core/quadrature.h"
#include "renderer/materials/microfacet.h"

namespace penumbra {
namespace {

constexpr int kN = kAlbedoTableRes;

float node(int i) { return float(i) / float(kN - 1); }

// E and E5 for one (mu, alpha) by quadrature over the visible normals of wi (Heitz 2018): the
// projected disk in polar coordinates, Gauss-Legendre in the polar angle psi (radius sin psi) and the
// midpoint rule in the angle (exponentially accurate for a periodic integrand). The estimator
// under the visible-normal density is G1(wo, m) (Heitz 2014 eq. 19), times (1 - wi.m)^5 for E5.
MicrofacetAlbedo integrate(float mu, float alpha) {
  static const auto rule = [] {
    std::vector<double> x, w;
    gauss_legendre(40, x, w);
    return std::make_pair(x, w);
  }();
  constexpr int kAngles = 32;
  // cos and sin of the midpoint rule's angles, the same for every node (computed once, not at
  // each of a node's 40 x 32 points).
  static const auto angles = [] {
    std::array<std::array<double, 2>, kAngles> cs{};
    for (int b = 0; b < kAngles; ++b) {
      const double phi = 2.0 * kPi * (b + 0.5) / kAngles;
      cs[size_t(b)] = {std::cos(phi), std::sin(phi)};
    }
    return cs;
  }();
  const GgxDistribution distr(alpha);
  const float c = std::max(mu, 1e-4f);
  const vec3 wi(std::sqrt(std::max(0.f, 1.f - c * c)), 0.f, c);
  // Heitz 2018 listing 1 with the disk in polar coordinates instead of a warp of the square.
  const StretchedView f = stretched_view(alpha, wi);
  double e = 0.0, e5 = 0.0;
  const auto& [x, w] = rule;
  for (size_t a = 0; a < x.size(); ++a) {
    // rho = sin(psi), psi in [0, pi/2]: the hemisphere's height cos(psi) is smooth in psi where
    // it is not in rho (sqrt(1 - rho^2) at the rim), so the rule converges fast.
    const double psi = 0.25 * kPi * (x[a] + 1.0);
    const double rho = std::sin(psi);
    const double w_rho = 0.25 * kPi * w[a] * 2.0 * rho * std::cos(psi);  // d(rho^2)
    for (int b = 0; b < kAngles; ++b) {
      const float p1 = float(rho * angles[size_t(b)][0]);
      const float p2d = float(rho * angles[size_t(b)][1]);
      const float p2 = (1.f - f.s) * safe_sqrt(1.f - p1 * p1) + f.s * p2d;
      const vec3 nh = p1 * f.t1 + p2 * f.t2 + safe_sqrt(1.f - p1 * p1 - p2 * p2) * f.vh;
      const vec3 m = glm::normalize(vec3(alpha * nh.x, alpha * nh.y, std::max(0.f, nh.z)));
      const vec3 wo = 2.f * glm::dot(wi, m) * m - wi;
      if (wo.z <= 0.f) continue;
      const double g1 = distr.smith_g1(wo, m);
      const double weight = w_rho / kAngles;
      const double one_minus = std::max(0.0, 1.0 - double(glm::dot(wi, m)));
      const double sq = one_minus * one_minus;
      e += weight * g1;
      e5 += weight * g1 * sq * sq * one_minus;
    }
  }
  return {float(e), float(e5)};
}

}  // namespace

MicrofacetAlbedoRow ggx_albedo_row_by_quadrature(int j) {
  MicrofacetAlbedoRow row;
  const float r = node(j);
  for (int i = 0; i < kN; ++i) {
    const float mu = node(i);
    // Roughness 0 is the smooth limit, exactly: all light reflects about the normal.
    row.albedo[i] = j == 0 ? MicrofacetAlbedo{1.f, std::pow(1.f - mu, 5.f)}
                           : integrate(mu, std::max(r * r, kMinMicrofacetAlpha));
  }
  // 2 \int E(mu) mu dmu of the piecewise-linear interpolant, exactly: on [a, b] with values
  // fa, fb the integral of the line times mu is (b - a) (fa (2a + b) + fb (a + 2b)) / 6.
  double e = 0.0, e5 = 0.0;
  for (int i = 0; i + 1 < kN; ++i) {
    const double a = node(i), b = node(i + 1);
    const auto& fa = row.albedo[i];
    const auto& fb = row.albedo[i + 1];
    e += (b - a) * (fa.e * (2 * a + b) + fb.e * (a + 2 * b)) / 6.0;
    e5 += (b - a) * (fa.e5 * (2 * a + b) + fb.e5 * (a + 2 * b)) / 6.0;
  }
  row.average = {float(2.0 * e), float(2.0 * e5)};
  return row;
}

namespace {

// The table as shipped (ggx_albedo_table.inc, written by tools/tables/generate_ggx_albedo_table
// from ggx_albedo_row_by_quadrature; a test checks them against each other): building it at
// start-up took 0.1-0.2 s of every glTF render.
struct Table {
  MicrofacetAlbedo albedo[kN][kN];  // [roughness node][cos node]
  MicrofacetAlbedo average[kN];
};
constexpr Table kTable = {
#include "renderer/materials/ggx_albedo_table.inc"
};

// Node index and fraction of x in [0, 1] on the table's uniform grid.
inline void locate(float x, int* i, float* f) {
  const float p = std::clamp(x, 0.f, 1.f) * float(kN - 1);
  *i = std::min(int(p), kN - 2);
  *f = p - float(*i);
}

inline MicrofacetAlbedo lerp(const MicrofacetAlbedo& a, const MicrofacetAlbedo& b, float f) {
  return {a.e + (b.e - a.e) * f, a.e5 + (b.e5 - a.e5) * f};
}

}  // namespace

MicrofacetAlbedo ggx_albedo(float cos_theta, float roughness) {
  int i, j;
  float fi, fj;
  locate(cos_theta, &i, &fi);
  locate(roughness, &j, &fj);
  const Table& t = kTable;
  return lerp(lerp(t.albedo[j][i], t.albedo[j][i + 1], fi),
              lerp(t.albedo[j + 1][i], t.albedo[j + 1][i + 1], fi), fj);
}

const float* ggx_albedo_table() {
  static_assert(sizeof(MicrofacetAlbedo) == 2 * sizeof(float));
  static_assert(sizeof(Table::albedo) == sizeof(float) * 2 * kN * kN);
  return &kTable.albedo[0][0].e;
}

MicrofacetAlbedo ggx_albedo_average(float roughness) {
  int j;
  float fj;
  locate(roughness, &j, &fj);
  return lerp(kTable.average[j], kTable.average[j + 1], fj);
}

}  // namespace penumbra
