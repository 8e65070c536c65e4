#pragma once
// Shared helpers of the BSDF tests: deterministic random numbers, directions, and the chi-square
// goodness-of-fit test of a material's sample() against its pdf() (pbrt-v4 / Mitsuba 3 style).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "renderer/materials/material.h"

namespace penumbra::test {

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  float next() {
    return std::min(std::uniform_real_distribution<float>(0.f, 1.f)(engine_), kOneMinusEpsilon);
  }
  vec2 next2() {
    const float a = next();
    return vec2(a, next());
  }

 private:
  std::mt19937_64 engine_;
};

inline float deg(float d) { return d * kPi / 180.f; }

// Unit direction from polar angle theta (from +z) and azimuth phi, in radians.
inline vec3 spherical(float theta, float phi) {
  return vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

inline vec3 uniform_sphere(Rng& rng) {
  const float z = 1.f - 2.f * rng.next();
  const float r = std::sqrt(std::max(0.f, 1.f - z * z));
  const float phi = 2.f * kPi * rng.next();
  return vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// Regularised upper incomplete gamma Q(a, x) (series for x < a + 1, Lentz continued fraction
// otherwise; Abramowitz & Stegun 6.5.29 and 6.5.31).
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(log_prefix));
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(log_prefix) * h;
}

// Adaptive (Gauss-Legendre 3x3) cubature of f over a rectangle; each step splits along the axis whose split
// changes the estimate most, so a lobe that is narrow in one coordinate only (e.g. a GGX peak at
// the pole in (cos theta, phi)) is not refined along the other.
class AdaptiveCubature {
 public:
  using Fn = std::function<double(double, double)>;
  explicit AdaptiveCubature(Fn f, int max_depth = 18) : f_(std::move(f)), max_depth_(max_depth) {}

  double integrate(double x0, double x1, double y0, double y1, double tol) {
    return refine(x0, x1, y0, y1, gauss3(x0, x1, y0, y1), tol, 0);
  }

 private:
  // 3x3 Gauss-Legendre rule: an open rule, so the integrand is never evaluated on a cell edge
  // (the horizon cos(theta) = 0 is a bin edge where pdf() jumps to 0).
  double gauss3(double x0, double x1, double y0, double y1) {
    static constexpr double kNode = 0.7745966692414834, kW0 = 5.0 / 9.0, kW1 = 8.0 / 9.0;
    const double t[3] = {-kNode, 0.0, kNode}, w[3] = {kW0, kW1, kW0};
    const double cx = 0.5 * (x0 + x1), hx = 0.5 * (x1 - x0);
    const double cy = 0.5 * (y0 + y1), hy = 0.5 * (y1 - y0);
    double s = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s += w[i] * w[j] * f_(cx + hx * t[i], cy + hy * t[j]);
    return s * hx * hy;
  }
  double refine(double x0, double x1, double y0, double y1, double whole, double tol, int depth) {
    const double xm = 0.5 * (x0 + x1), ym = 0.5 * (y0 + y1);
    const double ax = gauss3(x0, xm, y0, y1), bx = gauss3(xm, x1, y0, y1);
    const double ay = gauss3(x0, x1, y0, ym), by = gauss3(x0, x1, ym, y1);
    const double ex = std::abs(ax + bx - whole), ey = std::abs(ay + by - whole);
    const double refined = 0.5 * (ax + bx + ay + by);
    // The relative criterion stops refinement at the float precision of pdf(): an absolute
    // tolerance alone, halved at every level, would chase rounding noise to max_depth.
    if (depth >= max_depth_ || std::max(ex, ey) <= std::max(tol, 1e-4 * std::abs(refined)))
      return refined;
    if (ex >= ey)
      return refine(x0, xm, y0, y1, ax, 0.5 * tol, depth + 1) +
             refine(xm, x1, y0, y1, bx, 0.5 * tol, depth + 1);
    return refine(x0, x1, y0, ym, ay, 0.5 * tol, depth + 1) +
           refine(x0, x1, ym, y1, by, 0.5 * tol, depth + 1);
  }

  Fn f_;
  int max_depth_;
};

struct Chi2Config {
  int theta_res = 20;  // bins in cos(theta) over [-1, 1] (even: the horizon is a bin edge)
  int phi_res = 40;    // bins in phi over [0, 2 pi)
  int sub_res = 4;     // fixed sub-cells per bin and axis before adaptive refinement
  int samples = 200000;
  double min_expected = 5.0;
  double significance = 0.01;  // before the Sidak correction
  int num_tests = 1;           // number of chi-square tests in the suite (Sidak correction)
  uint64_t seed = 1;
};

struct Chi2Result {
  bool pass = false;
  double p_value = 0.0;
  double chi2 = 0.0;
  int dof = 0;
  std::string message;
};

// Histogram of the directions returned by sample() (non-delta samples; delta and invalid samples
// land in one extra "other" cell) against N times the integral of pdf() over each cell; the
// "other" cell expects N (1 - \int pdf). Low-expectation cells are pooled; the p-value is compared
// with the Sidak-corrected significance 1 - (1 - alpha)^(1 / num_tests).
// `mat`: anything answering sample() and pdf() as Material does (Material, SurfaceBsdf).
template <typename Bsdf>
Chi2Result chi2_test(const Bsdf& mat, const BsdfContext& ctx, const vec3& wi,
                     const Chi2Config& cfg) {
  const int nt = cfg.theta_res, np = cfg.phi_res, ncells = nt * np + 1;
  std::vector<double> observed(ncells, 0.0), expected(ncells, 0.0);

  Rng rng(cfg.seed);
  for (int i = 0; i < cfg.samples; ++i) {
    const float u_lobe = rng.next();
    const vec2 u = rng.next2();
    const auto bs = mat.sample(ctx, wi, u_lobe, u);
    if (!bs || bs->pdf == 0.f) {
      observed[ncells - 1] += 1.0;
      continue;
    }
    const float cos_t = std::clamp(bs->wo.z, -1.f, 1.f);
    float phi = std::atan2(bs->wo.y, bs->wo.x);
    if (phi < 0.f) phi += 2.f * kPi;
    const int ti = std::clamp(int((cos_t + 1.f) * 0.5f * nt), 0, nt - 1);
    const int pi = std::clamp(int(phi / (2.f * kPi) * np), 0, np - 1);
    observed[ti * np + pi] += 1.0;
  }

  AdaptiveCubature cubature([&](double c, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    const vec3 wo(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
    return double(mat.pdf(ctx, wi, wo));
  });
  double total = 0.0;
  const double dc = 2.0 / nt, dp = 2.0 * M_PI / np;
  const double sc = dc / cfg.sub_res, sp = dp / cfg.sub_res;
  for (int ti = 0; ti < nt; ++ti) {
    for (int pi = 0; pi < np; ++pi) {
      double integral = 0.0;
      for (int a = 0; a < cfg.sub_res; ++a)
        for (int b = 0; b < cfg.sub_res; ++b) {
          const double c0 = -1.0 + ti * dc + a * sc, p0 = pi * dp + b * sp;
          integral += cubature.integrate(c0, c0 + sc, p0, p0 + sp, 1e-8);
        }
      expected[ti * np + pi] = integral * cfg.samples;
      total += integral;
    }
  }
  expected[ncells - 1] = std::max(0.0, 1.0 - total) * cfg.samples;

  Chi2Result res;
  std::ostringstream msg;
  if (total > 1.0 + 1e-3) msg << "pdf integrates to " << total << " > 1; ";

  // Cells with no expectation but observed samples: sampling outside the pdf's support.
  for (int i = 0; i < ncells; ++i)
    if (expected[i] == 0.0 && observed[i] > cfg.samples * 1e-5) {
      msg << "cell " << i << " observed " << observed[i] << " but expected 0; ";
      res.message = msg.str();
      return res;
    }

  std::vector<int> order(ncells);
  for (int i = 0; i < ncells; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });
  double pooled_obs = 0.0, pooled_exp = 0.0;
  double chi2 = 0.0;
  int terms = 0;
  for (int idx : order) {
    if (expected[idx] == 0.0) continue;
    if (expected[idx] < cfg.min_expected || (pooled_exp > 0.0 && pooled_exp < cfg.min_expected)) {
      pooled_obs += observed[idx];
      pooled_exp += expected[idx];
      continue;
    }
    const double d = observed[idx] - expected[idx];
    chi2 += d * d / expected[idx];
    ++terms;
  }
  if (pooled_exp > 0.0) {
    const double d = pooled_obs - pooled_exp;
    chi2 += d * d / pooled_exp;
    ++terms;
  }
  res.dof = std::max(1, terms - 1);
  res.chi2 = chi2;
  res.p_value = gamma_q(0.5 * res.dof, 0.5 * chi2);
  const double alpha = 1.0 - std::pow(1.0 - cfg.significance, 1.0 / cfg.num_tests);
  res.pass = res.p_value >= alpha && total <= 1.0 + 1e-3;
  msg << "chi2 = " << chi2 << ", dof = " << res.dof << ", p = " << res.p_value
      << " (threshold " << alpha << "), pdf mass = " << total;
  res.message = msg.str();
  return res;
}

}  // namespace penumbra::test
