#pragma once
// Warps from the unit square to directions and points, with their densities.
#include "renderer/core/math.h"

namespace penumbra {

// Sine and cosine of |x| <= pi/4, the only angles the concentric map needs. Taylor polynomials
// to x^9 and x^10 in Horner form: their truncation error at pi/4 is below 2e-9 (x^11/11!,
// x^12/12!), far under float's half ulp, so what remains is the rounding of the few operations
// (at most 1.1 ulps against libm's 0.5; SamplingWarps.SinCosQuarterPi checks it). Inline
// arithmetic instead of libm's sincosf: no call and no range reduction on the path of every
// lens, diffuse and microfacet sample, and a loop over many samples can vectorise it.
inline void sincos_quarter_pi(float x, float* s, float* c) {
  const float x2 = x * x;
  *s = x * (1.f + x2 * (-1.f / 6.f + x2 * (1.f / 120.f + x2 * (-1.f / 5040.f + x2 * (1.f / 362880.f)))));
  *c = 1.f + x2 * (-0.5f + x2 * (1.f / 24.f + x2 * (-1.f / 720.f + x2 * (1.f / 40320.f +
                                                                          x2 * (-1.f / 3628800.f)))));
}

// Sine and cosine of 2 pi u (u in [0, 1) for the warps; any |u| < 2^29 works): 2 pi u = (pi/2)(k + f)
// with k the integer nearest 4u and f = 4u - k in [-1/2, 1/2], both exact in float (4u is a
// power-of-two scaling, and subtracting an integer within one half of it loses no bits), so the
// reduction adds no error and the quarter turn k only swaps and negates; one rounding of the
// angle f pi/2 plus sincos_quarter_pi's remains.
inline void sincos_two_pi(float u, float* s, float* c) {
  const float t = 4.f * u;
  const int k = int(t + std::copysign(0.5f, t));  // rounded half away from zero
  float a, b;
  sincos_quarter_pi((t - float(k)) * (kPi / 2.f), &a, &b);
  // Quarter turns k & 3 = 0, 1, 2, 3: (s, c) = (a, b), (b, -a), (-a, -b), (-b, a), as selects
  // (a loop over many angles vectorises).
  const float s0 = (k & 1) ? b : a, c0 = (k & 1) ? a : b;
  *s = (k & 2) ? -s0 : s0;
  *c = ((k + 1) & 2) ? -c0 : c0;
}

// Shirley & Chiu 1997 concentric map, unit disk. The second wedge's angle pi/2 - t is folded
// into t, swapping sine and cosine, so both wedges take angles within [-pi/4, pi/4].
inline vec2 square_to_disk_concentric(const vec2& u) {
  const float ox = 2.f * u.x - 1.f, oy = 2.f * u.y - 1.f;
  if (ox == 0.f && oy == 0.f) return vec2(0.f);
  float s, c;
  if (std::abs(ox) > std::abs(oy)) {
    sincos_quarter_pi((kPi / 4.f) * (oy / ox), &s, &c);
    return vec2(ox * c, ox * s);
  }
  sincos_quarter_pi((kPi / 4.f) * (ox / oy), &s, &c);
  return vec2(oy * s, oy * c);
}

// Malley's method: cosine-weighted hemisphere around +z; pdf = cos(theta) / pi.
inline vec3 square_to_cosine_hemisphere(const vec2& u) {
  const vec2 d = square_to_disk_concentric(u);
  return vec3(d.x, d.y, safe_sqrt(1.f - d.x * d.x - d.y * d.y));
}
inline float cosine_hemisphere_pdf(const vec3& w) { return w.z > 0.f ? w.z * kInvPi : 0.f; }

inline vec3 square_to_uniform_sphere(const vec2& u) {
  const float z = 1.f - 2.f * u.x;
  const float r = safe_sqrt(1.f - z * z);
  float s, c;
  sincos_two_pi(u.y, &s, &c);
  return vec3(r * c, r * s, z);
}
inline constexpr float uniform_sphere_pdf() { return kInv4Pi; }

// Uniform direction in the cone around +z with cos(theta) >= cos_max; pdf = 1 / (2 pi (1 - cos_max)).
inline vec3 square_to_uniform_cone(const vec2& u, float cos_max) {
  const float cos_t = 1.f - u.x * (1.f - cos_max);
  const float sin_t = safe_sqrt(1.f - cos_t * cos_t);
  float s, c;
  sincos_two_pi(u.y, &s, &c);
  return vec3(sin_t * c, sin_t * s, cos_t);
}
inline float uniform_cone_pdf(float cos_max) { return 1.f / (2.f * kPi * (1.f - cos_max)); }

// Uniform barycentrics (b1, b2) on a triangle: Heitz 2019, "A Low-Distortion Map Between
// Triangle and Square".
inline vec2 square_to_triangle(const vec2& u) {
  float b0, b1;
  if (u.y > u.x) {
    b0 = u.x / 2.f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.f;
    b0 = u.x - b1;
  }
  return vec2(b0, b1);
}

// Veach's power heuristic with beta = 2 (Veach 1997, eq. 9.13).
inline float power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0.f ? a / (a + b) : 0.f;
}

}  // namespace penumbra
