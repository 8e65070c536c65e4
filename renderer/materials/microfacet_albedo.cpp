#include "renderer/materials/microfacet_albedo.h"

#include <array>
#include <functional>
#include <mutex>
#include <vector>

#include <tbb/parallel_for.h>

#include "renderer/core/quadrature.h"
#include "renderer/materials/microfacet.h"

namespace penumbra {
namespace {

constexpr int kN = kAlbedoTableRes;

struct Table {
  // [roughness node][cos node]
  std::array<std::array<MicrofacetAlbedo, kN>, kN> albedo{};
  std::array<MicrofacetAlbedo, kN> average{};
  // Rows are built when first needed (ensure_rows): a scene whose glTF materials have one
  // roughness needs two of the 48, a few milliseconds instead of the whole table's 0.1 s.
  std::array<std::once_flag, kN> built;
};

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
  // cos and sin of the midpoint rule's angles, the same for every node (computed once: the
  // table's build is part of every glTF scene's start-up).
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

// Row j (roughness node j): E and E5 at every cos node, and their averages.
void build_row(Table& t, int j) {
  const float r = node(j);
  for (int i = 0; i < kN; ++i) {
    const float mu = node(i);
    // Roughness 0 is the smooth limit, exactly: all light reflects about the normal.
    t.albedo[j][i] = j == 0 ? MicrofacetAlbedo{1.f, std::pow(1.f - mu, 5.f)}
                            : integrate(mu, std::max(r * r, kMinMicrofacetAlpha));
  }
  // 2 \int E(mu) mu dmu of the piecewise-linear interpolant, exactly: on [a, b] with values
  // fa, fb the integral of the line times mu is (b - a) (fa (2a + b) + fb (a + 2b)) / 6.
  double e = 0.0, e5 = 0.0;
  for (int i = 0; i + 1 < kN; ++i) {
    const double a = node(i), b = node(i + 1);
    const auto& fa = t.albedo[j][i];
    const auto& fb = t.albedo[j][i + 1];
    e += (b - a) * (fa.e * (2 * a + b) + fb.e * (a + 2 * b)) / 6.0;
    e5 += (b - a) * (fa.e5 * (2 * a + b) + fb.e5 * (a + 2 * b)) / 6.0;
  }
  t.average[j] = {float(2.0 * e), float(2.0 * e5)};
}

Table& table() {
  static Table t;  // thread-safe initialisation (C++11 magic statics); rows built on demand
  return t;
}

// Rows j0..j1 built (each once, thread-safe: std::call_once); several in parallel.
const Table& ensure_rows(int j0, int j1) {
  Table& t = table();
  if (j1 - j0 < 2) {
    for (int j = j0; j <= j1; ++j) std::call_once(t.built[size_t(j)], build_row, std::ref(t), j);
  } else {
    tbb::parallel_for(j0, j1 + 1, [&](int j) {
      std::call_once(t.built[size_t(j)], build_row, std::ref(t), j);
    });
  }
  return t;
}

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
  const Table& t = ensure_rows(j, j + 1);
  return lerp(lerp(t.albedo[j][i], t.albedo[j][i + 1], fi),
              lerp(t.albedo[j + 1][i], t.albedo[j + 1][i + 1], fi), fj);
}

const float* ggx_albedo_table(float roughness_lo, float roughness_hi) {
  static_assert(sizeof(MicrofacetAlbedo) == 2 * sizeof(float));
  static_assert(sizeof(Table::albedo) == sizeof(float) * 2 * kN * kN);
  int j0, j1;
  float f;
  locate(roughness_lo, &j0, &f);
  locate(roughness_hi, &j1, &f);
  return &ensure_rows(j0, j1 + 1).albedo[0][0].e;
}

MicrofacetAlbedo ggx_albedo_average(float roughness) {
  int j;
  float fj;
  locate(roughness, &j, &fj);
  const Table& t = ensure_rows(j, j + 1);
  return lerp(t.average[j], t.average[j + 1], fj);
}

}  // namespace penumbra
