#pragma once
// The BSDF models of the surface stage (surface_stage.h) on one lane's scalars, for its loops
// over arrays: each model answers the two questions path_scatter asks its SurfaceBsdf, the value
// and pdf towards a light's direction (eval_pdf) and a sampled direction with its weight and
// pdf (sample), in the front-mirrored local frame (SurfaceBsdf mirrors a two-sided model's back
// side to its front; the stage does the mirroring). Each is its scalar model's arithmetic
// operation for operation (glm's dot is (x + y) + z, normalize multiplies by 1 / sqrt, std::max
// is its comparison), its branches selects between values every lane computes, so the stage's
// results are path_scatter's to the bit.
//
// A new model (a plastic, a dielectric) adds a struct of the same shape here, a kind in
// StageModel and the scene's surfaces it takes in SurfaceStage's constructor.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "renderer/core/math.h"
#include "renderer/render/light_kernels.h"
#include "renderer/sampling/sampling.h"

namespace penumbra::lane {

// Whether x is finite, as a mask made by integer arithmetic alone: |x|'s bits lie below
// infinity's. (As a comparison, GCC 12 folds several such masks into bools and selects between
// them, which its vectoriser does not support.)
[[gnu::always_inline]] inline Mask finite(float x) {
  int32_t b;
  std::memcpy(&b, &x, sizeof b);
  return ((b & 0x7fffffff) - 0x7f800000) >> 31;
}

// A lane's surface parameters: a colour and, for microfacet models, GGX alpha (already clamped
// to kMinMicrofacetAlpha as GgxDistribution holds it).
struct Params {
  float c[3];
  float alpha;
};

// The BSDF's answer towards a light: f (times the cosine) and the pdf of its own sampling.
struct EvalPdf {
  float f[3];
  float pdf;
};

// A sampled direction: wo in the front-mirrored local frame, weight = f cos / pdf, and whether
// the model gave a sample at all.
struct Sample {
  float wo[3];
  float weight[3];
  float pdf;
  Mask ok;
};

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

// DiffuseBsdf (materials/diffuse.h): f cos = colour cos_o / pi, cosine-weighted sampling.
struct Lambert {
  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params& q, const float* a,
                                                 const float* b) {
    EvalPdf r;
    const Mask zero = mask(a[2] <= 0.f) | mask(b[2] <= 0.f);
    // Zero where the model answers zero. (SurfaceBsdf also zeroes an answer that is not finite;
    // with b_z > 0 a cosine and the colour finite, which the stage requires, it always is.)
    const float cos_term = kInvPi * b[2];
    for (int c = 0; c < 3; ++c) r.f[c] = when(zero, 0.f, q.c[c] * cos_term);
    r.pdf = when(zero, 0.f, b[2] * kInvPi);
    return r;
  }

  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float u0,
                                              float u1) {
    Sample s;
    disk_concentric(u0, u1, &s.wo[0], &s.wo[1]);
    s.wo[2] = safe_root(1.f - s.wo[0] * s.wo[0] - s.wo[1] * s.wo[1]);
    s.pdf = s.wo[2] > 0.f ? s.wo[2] * kInvPi : 0.f;
    for (int c = 0; c < 3; ++c) s.weight[c] = q.c[c];
    // (SurfaceBsdf::sample's finiteness checks always pass here: the colour is finite, which the
    // stage requires, and for the sampler's values in [0, 1) so are the direction and the pdf.)
    s.ok = ~mask(a[2] <= 0.f) & mask(s.pdf > 0.f);
    return s;
  }
};

// ConductorBsdf (materials/conductor.h) when rough: GGX with Smith masking, visible-normal
// sampling (materials/microfacet.h: Walter et al. 2007 eq. 33-34, Heitz 2018 listing 1).
struct RoughConductor {
  [[gnu::always_inline]] static float dot3(const float* a, const float* b) {
    return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
  }
  // glm::normalize: v times 1 / sqrt(v.v).
  [[gnu::always_inline]] static void normalize(float* v) {
    const float k = 1.f / std::sqrt(dot3(v, v));
    for (int c = 0; c < 3; ++c) v[c] = v[c] * k;
  }
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

  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params& q, const float* a,
                                                 const float* b) {
    float h[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    normalize(h);
    const float d = ndf(q.alpha, h);
    const float g1_i = smith_g1(q.alpha, a, h);
    const float denom = 4.f * a[2];
    const float value = d * (g1_i * smith_g1(q.alpha, b, h)) / denom;
    const Mask zero = mask(a[2] <= 0.f) | mask(b[2] <= 0.f);
    const Mask has_value = ~zero & finite(value);
    EvalPdf r;
    for (int c = 0; c < 3; ++c) r.f[c] = when(has_value, q.c[c] * value, 0.f);
    // SurfaceBsdf zeroes a value with a component that is not finite.
    const Mask f_finite = finite(r.f[0]) & finite(r.f[1]) & finite(r.f[2]);
    for (int c = 0; c < 3; ++c) r.f[c] = when(f_finite, r.f[c], 0.f);
    const float p = d * g1_i / denom;
    r.pdf = when(~zero & mask(dot3(b, h) > 0.f) & finite(p), p, 0.f);
    return r;
  }

  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float u0,
                                              float u1) {
    const float alpha = q.alpha;
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
    float m[3] = {alpha * nh[0], alpha * nh[1], 0.f < nh[2] ? nh[2] : 0.f};
    normalize(m);
    // ConductorBsdf::sample: the mirror direction about m (fresnel.h's reflect), its pdf
    // (pdf_visible / (4 wo.m)) and weight colour G1(wo, m) (Heitz 2014 eq. 19).
    Sample r;
    const float two_dot = 2.f * dot3(a, m);
    for (int c = 0; c < 3; ++c) r.wo[c] = two_dot * m[c] - a[c];
    const float dot_wo_m = dot3(r.wo, m);
    const float visible = (ndf(alpha, m) * smith_g1(alpha, a, m)) * std::fabs(dot3(a, m)) / a[2];
    r.pdf = when(mask(a[2] <= 0.f), 0.f, visible) / (4.f * dot_wo_m);
    const float g1 = smith_g1(alpha, r.wo, m);
    for (int c = 0; c < 3; ++c) r.weight[c] = q.c[c] * g1;
    r.ok = ~mask(a[2] <= 0.f) & ~mask(r.wo[2] <= 0.f) & mask(r.pdf > 0.f) & finite(r.pdf) &
           mask(g1 > 0.f) & finite(r.weight[0]) & finite(r.weight[1]) & finite(r.weight[2]) &
           finite(r.wo[0]) & finite(r.wo[1]) & finite(r.wo[2]);
    return r;
  }
};

}  // namespace penumbra::lane
