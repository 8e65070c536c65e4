#pragma once
// The microfacet and Fresnel arithmetic of materials/ on one lane's scalars, for loops over
// arrays (the surface stages' models, render/lane_bsdfs.h; the coating tables' quadrature,
// materials/coating_tables_integrals.cpp): each function is its scalar counterpart's operations
// in the same order (glm's dot is (x + y) + z, normalize multiplies by 1 / sqrt, std::max is its
// comparison), its branches selects, so a loop of them gives the scalar results to the bit when
// compiled without FMA contraction.
#include <cmath>

#include "renderer/core/lane.h"
#include "renderer/core/math.h"
#include "renderer/sampling/sampling.h"

namespace penumbra::lane {

// square_to_disk_concentric (sampling.h; Shirley and Chiu 1997) of (u0, u1).
[[gnu::always_inline]] inline void disk_concentric(float u0, float u1, float* x, float* y) {
  const float ox = 2.f * u0 - 1.f, oy = 2.f * u1 - 1.f;
  const Mask centre = mask(ox == 0.f) & mask(oy == 0.f);
  const Mask wide = mask(std::fabs(ox) > std::fabs(oy));
  const float num = when(wide, oy, ox), den = when(wide, ox, oy), r = when(wide, ox, oy);
  float sn, cs;
  sincos_quarter_pi((kPi / 4.f) * (num / den), &sn, &cs);
  *x = when(centre, 0.f, when(wide, r * cs, r * sn));
  *y = when(centre, 0.f, when(wide, r * sn, r * cs));
}

// safe_sqrt (core/math.h): std::max(0.f, x) is (0 < x ? x : 0).
[[gnu::always_inline]] inline float safe_root(float x) { return std::sqrt(0.f < x ? x : 0.f); }

[[gnu::always_inline]] inline float dot3(const float* a, const float* b) {
  return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
}
// square_to_cosine_hemisphere (sampling.h): the concentric disk lifted to the hemisphere.
[[gnu::always_inline]] inline void cosine_hemisphere(float u0, float u1, float* w) {
  disk_concentric(u0, u1, &w[0], &w[1]);
  w[2] = safe_root(1.f - w[0] * w[0] - w[1] * w[1]);
}
// fresnel.h's reflect of a about the unit normal m: 2 (a.m) m - a.
[[gnu::always_inline]] inline void reflect(const float* a, const float* m, float* out) {
  const float two_dot = 2.f * dot3(a, m);
  for (int c = 0; c < 3; ++c) out[c] = two_dot * m[c] - a[c];
}
// std::clamp(x, 0.f, 1.f), NaN passing through as std::clamp's comparisons let it.
[[gnu::always_inline]] inline float clamp01(float x) { return x < 0.f ? 0.f : (1.f < x ? 1.f : x); }
// glm::normalize: v times 1 / sqrt(v.v).
[[gnu::always_inline]] inline void normalize(float* v) {
  const float k = 1.f / std::sqrt(dot3(v, v));
  for (int c = 0; c < 3; ++c) v[c] = v[c] * k;
}

// GgxDistribution (materials/microfacet.h: Walter et al. 2007 eq. 33-34, Heitz 2018 listing 1).
struct Ggx {
  // GgxDistribution::ndf.
  [[gnu::always_inline]] static float ndf(float alpha, const float* m) {
    const float a2 = alpha * alpha;
    const float t = (m[0] * m[0] + m[1] * m[1]) / a2 + m[2] * m[2];
    const float d = 1.f / (kPi * a2 * t * t);
    const Mask keep = mask(m[2] > 0.f) & mask(d * m[2] > 1e-20f) & finite(d);
    return when(keep, d, 0.f);
  }
  // GgxDistribution::smith_g1.
  [[gnu::always_inline]] static float smith_g1(float alpha, const float* v, const float* m) {
    const Mask back = mask(dot3(v, m) * v[2] <= 0.f);
    const float xy_a2 = alpha * alpha * (v[0] * v[0] + v[1] * v[1]);
    const float tan2_a2 = xy_a2 / (v[2] * v[2]);
    const float g = 2.f / (1.f + std::sqrt(1.f + tan2_a2));
    return when(back, 0.f, when(mask(xy_a2 == 0.f), 1.f, g));
  }

  // GgxDistribution::sample_visible into m.
  [[gnu::always_inline]] static void sample_visible(float alpha, const float* a, float u0,
                                                    float u1, float* m) {
    // stretched_view (microfacet.h): the view at alpha = 1 and two tangents around it.
    float vh[3] = {alpha * a[0], alpha * a[1], a[2]};
    normalize(vh);
    const float len2 = vh[0] * vh[0] + vh[1] * vh[1];
    const float root = std::sqrt(len2);
    const Mask tilted = mask(len2 > 0.f);
    const float t1[3] = {when(tilted, -vh[1] / root, 1.f), when(tilted, vh[0] / root, 0.f),
                         0.f};  // (0 / root is +0 as well)
    // glm::cross(vh, t1).
    const float t2[3] = {vh[1] * t1[2] - t1[1] * vh[2], vh[2] * t1[0] - t1[2] * vh[0],
                         vh[0] * t1[1] - t1[0] * vh[1]};
    const float s = 0.5f * (1.f + vh[2]);
    // GgxDistribution::sample_visible.
    float p1, py;
    disk_concentric(u0, u1, &p1, &py);
    const float p2 = (1.f - s) * safe_root(1.f - p1 * p1) + s * py;
    const float k = safe_root(1.f - p1 * p1 - p2 * p2);
    float nh[3];
    for (int c = 0; c < 3; ++c) nh[c] = (p1 * t1[c] + p2 * t2[c]) + k * vh[c];
    m[0] = alpha * nh[0];
    m[1] = alpha * nh[1];
    m[2] = 0.f < nh[2] ? nh[2] : 0.f;
    normalize(m);
  }
};

// fresnel_dielectric (materials/fresnel.cpp).
struct Fresnel {
  float reflectance, cos_t, eta_it, eta_ti;
};
[[gnu::always_inline]] inline Fresnel fresnel_dielectric(float cos_i, float eta) {
  const Mask outside = mask(cos_i >= 0.f);
  const float inverse = 1.f / eta;
  const float eta_it = when(outside, eta, inverse), eta_ti = when(outside, inverse, eta);
  const float sin2 = 1.f - cos_i * cos_i;
  const float cos_t_sqr = 1.f - eta_ti * eta_ti * (0.f < sin2 ? sin2 : 0.f);
  const float ci = std::fabs(cos_i);
  const float ct = std::sqrt(cos_t_sqr);
  const float r_s = (ci - eta_it * ct) / (ci + eta_it * ct);
  const float r_p = (ct - eta_it * ci) / (ct + eta_it * ci);
  const float half = 0.5f * (r_s * r_s + r_p * r_p);
  const float f = half < 1.f ? half : 1.f;
  const Mask matched = mask(eta == 1.f);
  const Mask total = ~matched & mask(cos_t_sqr <= 0.f);  // total internal reflection
  const Mask grazing = ~matched & ~total & mask(ci == 0.f);
  Fresnel r;
  r.reflectance = when(matched, 0.f, when(total | grazing, 1.f, f));
  r.cos_t = when(matched, -cos_i, when(total, 0.f, when(outside, -ct, ct)));
  r.eta_it = when(matched, 1.f, eta_it);
  r.eta_ti = when(matched, 1.f, eta_ti);
  return r;
}
[[gnu::always_inline]] inline float fresnel_reflectance(float cos_i, float eta) {
  return fresnel_dielectric(cos_i, eta).reflectance;
}

}  // namespace penumbra::lane
