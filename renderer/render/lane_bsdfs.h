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
// Each model says whether it is two-sided (kTwoSided) and whether all its lobes are Dirac
// deltas (kDeltaOnly: path_scatter then estimates no direct light there, and the model answers
// no eval_pdf). A new model adds a struct of the same shape here, a kind in StageModel and the
// scene's surfaces it takes in SurfaceStage's constructor.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "renderer/core/math.h"
#include "renderer/materials/lane_microfacet.h"
#include "renderer/materials/microfacet_albedo.h"
#include "renderer/render/light_kernels.h"
#include "renderer/sampling/sampling.h"

namespace penumbra::lane {

// The coating tables of a stage's plastics (CoatingTables' cosines and transmittance arrays,
// kCoatingTableCapacity entries per table, one table after another).
struct Tables {
  const float* cosines;
  const float* transmittance;
  const float* ggx_albedo;  // materials/microfacet_albedo.h's ggx_albedo_table()
};

// A lane's surface parameters: a colour; for microfacet models GGX alpha (already clamped to
// kMinMicrofacetAlpha as GgxDistribution holds it); for plastics the coating's ior, the
// coating's sampling weight, the diffuse factor and its table (first entry and node count);
// for glTF's metallic-roughness model its metallic factor, roughness (the albedo table's
// coordinate), E_avg, E_F,avg of the dielectric and F_ms of the metal.
struct Params {
  float c[3];
  float alpha;
  float eta, spec_weight, diffuse_scale;
  int32_t table, nodes;
  Tables tables;
  float metallic, roughness, e_avg, dielectric_avg, f_ms[3];
};

// The BSDF's answer towards a light: f (times the cosine) and the pdf of its own sampling.
// `exact`: whether the lane could repeat the model exactly (a table lookup that resolves in a
// bounded number of steps); a lane that could not takes path_scatter.
struct EvalPdf {
  float f[3];
  float pdf;
  Mask exact = -1;
};

// A model's answer is zero where wi (a) or wo (b) lies below the surface.
[[gnu::always_inline]] inline void zero_below_surface(const float* a, const float* b, EvalPdf* r) {
  const Mask zero = mask(a[2] <= 0.f) | mask(b[2] <= 0.f);
  for (int c = 0; c < 3; ++c) r->f[c] = when(zero, 0.f, r->f[c]);
  r->pdf = when(zero, 0.f, r->pdf);
}

// SurfaceBsdf zeroes a value with a component that is not finite, and such a pdf.
[[gnu::always_inline]] inline void clean_answer(EvalPdf* r) {
  const Mask f_finite = finite(r->f[0]) & finite(r->f[1]) & finite(r->f[2]);
  for (int c = 0; c < 3; ++c) r->f[c] = when(f_finite, r->f[c], 0.f);
  r->pdf = when(finite(r->pdf), r->pdf, 0.f);
}

// A sampled direction: wo in the front-mirrored local frame, weight = f cos / pdf, whether the
// model gave a sample at all, whether it is a Dirac lobe's (pdf 0), and `exact` as above.
struct Sample {
  float wo[3];
  float weight[3];
  float pdf;
  Mask ok;
  Mask delta = 0;
  Mask exact = -1;
  float eta = 1.f;  // the relative ior crossed (a refraction's), for Russian roulette
};

// DiffuseBsdf (materials/diffuse.h): f cos = colour cos_o / pi, cosine-weighted sampling.
struct Lambert {
  static constexpr bool kTwoSided = true;
  static constexpr bool kDeltaOnly = false;
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

  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float /*u_lobe*/,
                                              float u0, float u1) {
    Sample s;
    cosine_hemisphere(u0, u1, s.wo);
    s.pdf = s.wo[2] > 0.f ? s.wo[2] * kInvPi : 0.f;
    for (int c = 0; c < 3; ++c) s.weight[c] = q.c[c];
    // (SurfaceBsdf::sample's finiteness checks always pass here: the colour is finite, which the
    // stage requires, and for the sampler's values in [0, 1) so are the direction and the pdf.)
    s.ok = ~mask(a[2] <= 0.f) & mask(s.pdf > 0.f);
    return s;
  }
};

// ConductorBsdf (materials/conductor.h) when rough: GGX with Smith masking, visible-normal
// sampling.
struct RoughConductor {
  static constexpr bool kTwoSided = true;
  static constexpr bool kDeltaOnly = false;
  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params& q, const float* a,
                                                 const float* b) {
    float h[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    normalize(h);
    const float d = Ggx::ndf(q.alpha, h);
    const float g1_i = Ggx::smith_g1(q.alpha, a, h);
    const float denom = 4.f * a[2];
    const float value = d * (g1_i * Ggx::smith_g1(q.alpha, b, h)) / denom;
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

  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float /*u_lobe*/,
                                              float u0, float u1) {
    const float alpha = q.alpha;
    float m[3];
    Ggx::sample_visible(alpha, a, u0, u1, m);
    // ConductorBsdf::sample: the mirror direction about m (fresnel.h's reflect), its pdf
    // (pdf_visible / (4 wo.m)) and weight colour G1(wo, m) (Heitz 2014 eq. 19).
    Sample r;
    lane::reflect(a, m, r.wo);
    const float dot_wo_m = dot3(r.wo, m);
    const float visible = (Ggx::ndf(alpha, m) * Ggx::smith_g1(alpha, a, m)) * std::fabs(dot3(a, m)) / a[2];
    r.pdf = when(mask(a[2] <= 0.f), 0.f, visible) / (4.f * dot_wo_m);
    const float g1 = Ggx::smith_g1(alpha, r.wo, m);
    for (int c = 0; c < 3; ++c) r.weight[c] = q.c[c] * g1;
    r.ok = ~mask(a[2] <= 0.f) & ~mask(r.wo[2] <= 0.f) & mask(r.pdf > 0.f) & finite(r.pdf) &
           mask(g1 > 0.f) & finite(r.weight[0]) & finite(r.weight[1]) & finite(r.weight[2]) &
           finite(r.wo[0]) & finite(r.wo[1]) & finite(r.wo[2]);
    return r;
  }
};

// PlasticBsdf (materials/plastic.h): a Lambertian base under a dielectric coating, the coating's
// lobe and the base's sampled by a choice weighted by their reflectances. The parts both
// coatings share; `Coating` says what differs: the transmittance t(cos) through the coating
// (smooth: 1 - F; rough: the table) and the rough coating's own lobe.
template <class Coating>
struct Plastic {
  static constexpr bool kTwoSided = true;
  static constexpr bool kDeltaOnly = false;
  // PlasticBsdf::specular_probability with both lobes enabled; t_i = t(cos_i).
  [[gnu::always_inline]] static float specular_probability(const Params& q, float t_i) {
    const float p_spec = (1.f - t_i) * q.spec_weight;
    const float p_diff = t_i * (1.f - q.spec_weight);
    const float sum = p_spec + p_diff;
    return when(mask(sum > 0.f), p_spec / sum, 0.f);
  }

  // PlasticBsdf::evaluate<true, true> (its own answer, which sample weighs with; eval_pdf
  // cleans it as SurfaceBsdf does). `exact` collects the table lookups' exactness.
  [[gnu::always_inline]] static EvalPdf evaluate(const Params& q, const float* a, const float* b,
                                                 Mask* exact) {
    const float t_i = Coating::transmittance(q, a[2], exact);
    const float p_spec = specular_probability(q, t_i);
    EvalPdf r;
    float spec, spec_pdf;
    const Mask has_spec = Coating::lobe(q, a, b, &spec, &spec_pdf);
    const float t = t_i * Coating::transmittance(q, b[2], exact);
    const float k = t * q.diffuse_scale * kInvPi * b[2];
    for (int c = 0; c < 3; ++c) r.f[c] = when(has_spec, 0.f + spec, 0.f) + q.c[c] * k;
    const float p = (1.f - p_spec) * (b[2] > 0.f ? b[2] * kInvPi : 0.f);
    r.pdf = when(mask(p_spec > 0.f) & mask(Coating::kRough) & finite(spec_pdf),
                 p + p_spec * spec_pdf, p);
    zero_below_surface(a, b, &r);
    return r;
  }

  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params& q, const float* a,
                                                 const float* b) {
    Mask exact = -1;
    EvalPdf r = evaluate(q, a, b, &exact);
    clean_answer(&r);
    r.exact = exact;
    return r;
  }

  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float u_lobe,
                                              float u0, float u1) {
    Mask exact = -1;
    const float t_i = Coating::transmittance(q, a[2], &exact);
    const Mask pick_spec = mask(u_lobe < specular_probability(q, t_i));
    // The base's direction: square_to_cosine_hemisphere; the coating's: Coating::reflect.
    float wo[3];
    cosine_hemisphere(u0, u1, wo);
    float spec_wo[3];
    Coating::reflect(q, a, u0, u1, spec_wo);
    Sample r;
    for (int c = 0; c < 3; ++c) r.wo[c] = when(pick_spec, spec_wo[c], wo[c]);
    // One-sample MIS over the lobes: the mixture's pdf, weight f / pdf.
    const EvalPdf e = evaluate(q, a, r.wo, &exact);
    r.pdf = e.pdf;
    for (int c = 0; c < 3; ++c) r.weight[c] = e.f[c] / e.pdf;
    Mask ok = ~mask(r.wo[2] <= 0.f) & mask(r.pdf > 0.f);
    // A smooth coating's Dirac reflection: weight F / P(coating), no pdf.
    const Mask delta = pick_spec & mask(!Coating::kRough);
    const float w_delta = fresnel_reflectance(a[2], q.eta) / specular_probability(q, t_i);
    for (int c = 0; c < 3; ++c) r.weight[c] = when(delta, w_delta, r.weight[c]);
    r.pdf = when(delta, 0.f, r.pdf);
    ok = when(delta, Mask(-1), ok);
    // SurfaceBsdf::sample's checks.
    r.ok = ~mask(a[2] <= 0.f) & ok & finite(r.weight[0]) & finite(r.weight[1]) &
           finite(r.weight[2]) & finite(r.pdf) & finite(r.wo[0]) & finite(r.wo[1]) &
           finite(r.wo[2]);
    r.delta = delta;
    r.exact = exact;
    return r;
  }
};

// A smooth coating: t = 1 - F(cos), a Dirac reflection (reflect_local) and no lobe of its own
// towards a light.
struct SmoothCoating {
  static constexpr bool kRough = false;
  [[gnu::always_inline]] static float transmittance(const Params& q, float cos_theta, Mask*) {
    return 1.f - fresnel_reflectance(cos_theta, q.eta);
  }
  [[gnu::always_inline]] static Mask lobe(const Params&, const float*, const float*, float* f,
                                          float* pdf) {
    *f = 0.f;
    *pdf = 0.f;
    return 0;
  }
  [[gnu::always_inline]] static void reflect(const Params&, const float* a, float, float,
                                             float* wo) {
    wo[0] = -a[0];
    wo[1] = -a[1];
    wo[2] = a[2];
  }
};

// A rough GGX coating: t(cos) from the coating's table (PlasticBsdf::external_transmittance),
// the Torrance-Sparrow lobe with the dielectric Fresnel term, visible-normal sampling.
struct RoughCoating {
  static constexpr bool kRough = true;
  [[gnu::always_inline]] static float transmittance(const Params& q, float cos_theta,
                                                    Mask* exact) {
    const float lo = cos_theta < 0.f ? 0.f : cos_theta;  // std::clamp(cos_theta, 0.f, 1.f)
    const float mu = 1.f < lo ? 1.f : lo;
    // CoatingTables::interval on square nodes: the guess from sqrt(mu), then its corrections
    // one step each way (only the step up ever happens on the tables in use: the test checks
    // every node); a lane whose answer needed more than that is not exact (the scalar step,
    // whose loops run on, takes it). Entries as offsets from the tables' start, in int32, so
    // the lookups are gathers from one base.
    const float* cosines = q.tables.cosines;
    const int32_t first = q.table, last = q.table + q.nodes - 2;
    const float root = mu > 0.f ? std::sqrt(mu) : 0.f;  // (mu <= 1 already, and not NaN)
    const int32_t guess = first + int32_t(root * float(q.nodes - 1));
    int32_t i = last < guess ? last : guess;
    i -= mask(i < last) & mask(cosines[i + 1] <= mu);
    const Mask up_again = mask(i < last) & mask(cosines[i + 1] <= mu);
    i += mask(i > first) & mask(cosines[i] > mu);
    const Mask down_again = mask(i > first) & mask(cosines[i] > mu);
    *exact &= ~up_again & ~down_again;
    const float c0 = cosines[i], c1 = cosines[i + 1];
    const float width = c1 - c0;
    const float w = width > 0.f ? (mu - c0) / width : 1.f;
    return (1.f - w) * q.tables.transmittance[i] + w * q.tables.transmittance[i + 1];
  }
  // The coating's f cos and its sampling density towards b; whether f counts (finite).
  [[gnu::always_inline]] static Mask lobe(const Params& q, const float* a, const float* b,
                                          float* f, float* pdf) {
    float h[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    normalize(h);
    const float d = Ggx::ndf(q.alpha, h);
    const float g1_i = Ggx::smith_g1(q.alpha, a, h);
    const float fresnel = fresnel_reflectance(dot3(a, h), q.eta);
    // Walter et al. 2007 eq. 20 with the dielectric Fresnel term, G = G1 G1.
    *f = fresnel * d * (g1_i * Ggx::smith_g1(q.alpha, b, h)) / (4.f * a[2]);
    // Visible-normal density times the reflection Jacobian 1 / (4 wo.h).
    *pdf = d * g1_i / (4.f * a[2]);
    return finite(*f);
  }
  [[gnu::always_inline]] static void reflect(const Params& q, const float* a, float u0,
                                             float u1, float* wo) {
    float m[3];
    Ggx::sample_visible(q.alpha, a, u0, u1, m);
    lane::reflect(a, m, wo);  // (the free function, not this member)
  }
};

using SmoothPlastic = Plastic<SmoothCoating>;
using RoughPlastic = Plastic<RoughCoating>;

// DielectricBsdf (materials/dielectric.h) when rough and not index-matched: Walter et al. 2007's
// GGX reflection and refraction, visible normals sampled from the side wi is on, the lobe chosen
// by Fresnel. One-sided: the back is the interior (`eta` of the lane is the interior's ior).
struct RoughDielectric {
  static constexpr bool kTwoSided = false;
  static constexpr bool kDeltaOnly = false;

  // DielectricBsdf::half_vector: the generalised half vector m towards +z, the relative ior
  // eta = eta_o / eta_i, whether wi and wo reflect; the mask says whether they form a valid
  // configuration.
  [[gnu::always_inline]] static Mask half_vector(const Params& q, const float* a, const float* b,
                                                 float* m, float* eta, Mask* reflection) {
    *reflection = mask(a[2] * b[2] > 0.f);
    *eta = a[2] > 0.f ? q.eta : 1.f / q.eta;
    float h[3];
    for (int c = 0; c < 3; ++c) h[c] = when(*reflection, a[c] + b[c], a[c] + *eta * b[c]);
    const float len = std::sqrt(dot3(h, h));
    for (int c = 0; c < 3; ++c) h[c] = h[c] / len;
    const Mask below = mask(h[2] < 0.f);
    for (int c = 0; c < 3; ++c) m[c] = when(below, -h[c], h[c]);
    return mask(len > 0.f) & mask(dot3(a, m) * a[2] > 0.f) & mask(dot3(b, m) * b[2] > 0.f);
  }

  // DielectricBsdf::evaluate<true, true> with both lobes enabled, cleaned as SurfaceBsdf does.
  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params& q, const float* a,
                                                 const float* b) {
    float m[3], eta;
    Mask reflection;
    const Mask valid = half_vector(q, a, b, m, &eta, &reflection) & ~mask(a[2] == 0.f) &
                       ~mask(b[2] == 0.f);
    const float d = Ggx::ndf(q.alpha, m);
    const float g1_i = Ggx::smith_g1(q.alpha, a, m);
    const float dot_i = dot3(a, m), dot_o = dot3(b, m);
    const float f = fresnel_reflectance(dot_i, q.eta);
    const float denom = dot_i + eta * dot_o;
    const float g = g1_i * Ggx::smith_g1(q.alpha, b, m);
    // Walter et al. 2007 eq. 20 and 21 times |cos_o| (the refraction's 1/eta^2 radiance
    // scaling cancels its eta^2).
    const float reflected = f * d * g / (4.f * std::fabs(a[2]));
    const float refracted = std::fabs((1.f - f) * d * g * dot_i * dot_o / (a[2] * denom * denom));
    const float value = when(reflection, reflected, refracted);
    EvalPdf r;
    for (int c = 0; c < 3; ++c) r.f[c] = when(valid & finite(value), value, 0.f);
    // Jacobians dm/dwo: eq. 14 and 17; the visible-normal density of wi's side.
    const float jacobian = when(reflection, 1.f / (4.f * std::fabs(dot_o)),
                                eta * eta * std::fabs(dot_o) / (denom * denom));
    const Mask front = mask(a[2] > 0.f);
    const float wf[3] = {when(front, a[0], -a[0]), when(front, a[1], -a[1]),
                         when(front, a[2], -a[2])};
    const float p_m = when(mask(wf[2] <= 0.f), 0.f, d * g1_i * std::fabs(dot3(wf, m)) / wf[2]);
    const float p = p_m * jacobian * when(reflection, f, 1.f - f);
    r.pdf = when(valid & finite(p), p, 0.f);
    return r;
  }

  // DielectricBsdf::sample_rough with both lobes enabled.
  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float u_lobe,
                                              float u0, float u1) {
    const Mask front = mask(a[2] > 0.f);
    const float wf[3] = {when(front, a[0], -a[0]), when(front, a[1], -a[1]),
                         when(front, a[2], -a[2])};
    float m[3];
    Ggx::sample_visible(q.alpha, wf, u0, u1, m);
    const float pdf_m = when(mask(wf[2] <= 0.f), 0.f,
                             Ggx::ndf(q.alpha, m) * Ggx::smith_g1(q.alpha, wf, m) *
                                 std::fabs(dot3(wf, m)) / wf[2]);
    const float dot_i = dot3(a, m);
    const Fresnel fr = fresnel_dielectric(dot_i, q.eta);
    const Mask pick_r = mask(u_lobe < fr.reflectance);
    const float pdf = pdf_m * when(pick_r, fr.reflectance, 1.f - fr.reflectance);
    Sample r;
    // Reflection (fresnel.h's reflect) or refraction (refract) about m.
    const float two_dot = 2.f * dot_i;
    const float k = dot_i * fr.eta_ti + fr.cos_t;
    for (int c = 0; c < 3; ++c)
      r.wo[c] = when(pick_r, two_dot * m[c] - a[c], m[c] * k - a[c] * fr.eta_ti);
    const float side = r.wo[2] * a[2];
    const float dot_o = dot3(r.wo, m);
    const float denom = dot_i + fr.eta_it * dot_o;
    const float jacobian = when(pick_r, 1.f / (4.f * std::fabs(dot_o)),
                                fr.eta_it * fr.eta_it * std::fabs(dot_o) / (denom * denom));
    // With visible-normal sampling f |cos_o| / pdf reduces to G1(wo, m) (Heitz 2014 eq. 19),
    // times 1/eta^2 for the refracted radiance.
    const float g1 = Ggx::smith_g1(q.alpha, r.wo, m);
    const float weight = when(pick_r, 1.f, 1.f * (fr.eta_ti * fr.eta_ti)) * g1;
    r.pdf = pdf * jacobian;
    for (int c = 0; c < 3; ++c) r.weight[c] = weight;
    r.eta = when(pick_r, 1.f, fr.eta_it);
    r.ok = ~mask(a[2] == 0.f) & mask(pdf_m > 0.f) & mask(pdf > 0.f) &
           when(pick_r, ~mask(side <= 0.f), ~mask(side >= 0.f)) & mask(weight > 0.f) &
           mask(r.pdf > 0.f) & finite(r.pdf) & finite(weight) & finite(r.wo[0]) &
           finite(r.wo[1]) & finite(r.wo[2]);
    return r;
  }
};

// ConductorBsdf when smooth: a mirror of the colour's reflectance.
struct SmoothConductor {
  static constexpr bool kTwoSided = true;
  static constexpr bool kDeltaOnly = true;
  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params&, const float*, const float*) {
    return EvalPdf{{0.f, 0.f, 0.f}, 0.f};
  }
  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float, float,
                                              float) {
    Sample r;
    r.wo[0] = -a[0];  // reflect_local
    r.wo[1] = -a[1];
    r.wo[2] = a[2];
    for (int c = 0; c < 3; ++c) r.weight[c] = q.c[c];
    r.pdf = 0.f;
    r.delta = -1;
    r.ok = ~mask(a[2] <= 0.f) & finite(r.wo[0]) & finite(r.wo[1]) & finite(r.wo[2]);
    return r;
  }
};

// DielectricBsdf when smooth and not index-matched: Dirac reflection or refraction, chosen by
// Fresnel (weight 1, times 1/eta^2 for the refracted radiance).
struct SmoothDielectric {
  static constexpr bool kTwoSided = false;
  static constexpr bool kDeltaOnly = true;
  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params&, const float*, const float*) {
    return EvalPdf{{0.f, 0.f, 0.f}, 0.f};
  }
  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float u_lobe,
                                              float, float) {
    const Fresnel fr = fresnel_dielectric(a[2], q.eta);
    const Mask pick_r = mask(u_lobe < fr.reflectance);
    Sample r;
    // reflect_local or refract_local.
    r.wo[0] = when(pick_r, -a[0], -fr.eta_ti * a[0]);
    r.wo[1] = when(pick_r, -a[1], -fr.eta_ti * a[1]);
    r.wo[2] = when(pick_r, a[2], fr.cos_t);
    const float weight = when(pick_r, 1.f, 1.f * (fr.eta_ti * fr.eta_ti));
    for (int c = 0; c < 3; ++c) r.weight[c] = weight;
    r.pdf = 0.f;
    r.delta = -1;
    r.eta = when(pick_r, 1.f, fr.eta_it);
    r.ok = ~mask(a[2] == 0.f) & finite(weight) & finite(r.wo[0]) & finite(r.wo[1]) &
           finite(r.wo[2]);
    return r;
  }
};

// ggx_albedo (materials/microfacet_albedo.cpp) on one lane: the bilinear lookup, its locate
// and lerp operation for operation, the four nodes gathered from the table.
struct Albedo {
  float e, e5;
};
[[gnu::always_inline]] inline void albedo_locate(float x, int32_t* i, float* f) {
  constexpr int32_t kN = kAlbedoTableRes;
  const float p = clamp01(x) * float(kN - 1);
  const int32_t k = int32_t(p);
  const int32_t node = kN - 2 < k ? kN - 2 : k;  // std::min
  *f = p - float(node);
  // (A NaN x, which only a lane the model answers zero for can hold, converts to INT_MIN: kept
  // inside the table.)
  *i = node < 0 ? 0 : node;
}
[[gnu::always_inline]] inline Albedo ggx_albedo(const float* table, float mu, float roughness) {
  constexpr int32_t kN = kAlbedoTableRes;
  int32_t i, j;
  float fi, fj;
  albedo_locate(mu, &i, &fi);
  albedo_locate(roughness, &j, &fj);
  const int32_t k0 = 2 * (j * kN + i), k1 = k0 + 2 * kN;
  const float e0 = table[k0] + (table[k0 + 2] - table[k0]) * fi;
  const float e50 = table[k0 + 1] + (table[k0 + 3] - table[k0 + 1]) * fi;
  const float e1 = table[k1] + (table[k1 + 2] - table[k1]) * fi;
  const float e51 = table[k1 + 1] + (table[k1 + 3] - table[k1 + 1]) * fi;
  return {e0 + (e1 - e0) * fj, e50 + (e51 - e50) * fj};
}

// MetallicRoughnessBsdf (materials/metallic_roughness.h) when rough (not the smooth limit's
// Dirac mirror): a Lambertian base under an f0 = 0.04 GGX layer mixed with a GGX metal by the
// metallic factor, albedo-scaled (Kulla and Conty 2017); the specular lobe and the diffuse-like
// part chosen in proportion to their albedos towards wi, one-sample MIS over the two.
struct MetallicRoughness {
  static constexpr bool kTwoSided = true;
  static constexpr bool kDeltaOnly = false;
  static constexpr float kF0 = 0.04f;  // MetallicRoughnessBsdf::kDielectricF0
  [[gnu::always_inline]] static float positive(float x) { return 0.f < x ? x : 0.f; }  // max(0, x)
  // specular_probability with both lobes enabled, from wi's albedo a.
  [[gnu::always_inline]] static float specular_probability(const Params& q, const Albedo& a) {
    const float ei = kF0 * (a.e - a.e5) + a.e5;
    const float one_m = 1.f - q.metallic;
    const float kd = one_m * positive(1.f - ei);
    const float km = q.metallic * positive(1.f - a.e);
    float dv[3], sv[3];
    for (int c = 0; c < 3; ++c) {
      dv[c] = kd * q.c[c] + km * q.f_ms[c];
      // specular_albedo: Schlick is linear in f0.
      const float metal = q.c[c] * (a.e - a.e5) + a.e5;
      sv[c] = one_m * ei + q.metallic * metal;
    }
    const float d = ((dv[0] + dv[1]) + dv[2]) / 3.f;
    const float s = ((sv[0] + sv[1]) + sv[2]) / 3.f;
    const float ratio = s / (s + d);
    const float clamped = ratio < 0.05f ? 0.05f : (0.95f < ratio ? 0.95f : ratio);
    return when(~mask(d > 0.f), 1.f, when(~mask(s > 0.f), 0.f, clamped));
  }
  // MetallicRoughnessBsdf::evaluate<true, true> with every lobe (sample weighs with it;
  // eval_pdf cleans it as SurfaceBsdf does); ai = wi's albedo, p_spec = specular_probability
  // (q, ai), which sample has already (computed once there, GCC vectorises the loop).
  [[gnu::always_inline]] static EvalPdf evaluate(const Params& q, const float* a, const float* b,
                                                 const Albedo& ai, float p_spec) {
    const Albedo ao = ggx_albedo(q.tables.ggx_albedo, b[2], q.roughness);
    float h[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    normalize(h);
    const float d = Ggx::ndf(q.alpha, h);
    const float g1_i = Ggx::smith_g1(q.alpha, a, h);
    // diffuse_value: the dielectric's albedo-scaled base, then the metal's multiple scattering.
    const float one_m = 1.f - q.metallic;
    const float ei = kF0 * (ai.e - ai.e5) + ai.e5;
    const float eo = kF0 * (ao.e - ao.e5) + ao.e5;
    const float floor_avg = 1.f - q.dielectric_avg;
    const float scale_d =
        positive(1.f - ei) * positive(1.f - eo) / (kPi * (1e-6f < floor_avg ? floor_avg : 1e-6f));
    const Mask has_d = mask(q.metallic < 1.f);
    const Mask has_m = mask(q.metallic > 0.f) & mask(1.f - q.e_avg > 1e-6f);
    const float scale_m = positive(1.f - ai.e) * positive(1.f - ao.e) / (kPi * (1.f - q.e_avg));
    // The specular lobe: Walter et al. 2007 eq. 20 times cos_o, Schlick's Fresnel at wi.h.
    const float s = d * (g1_i * Ggx::smith_g1(q.alpha, b, h)) / (4.f * a[2]);
    const float cos_ih = dot3(a, h);
    const float x = 1.f - cos_ih;
    const float xc = clamp01(x);
    const float x2 = xc * xc;
    const float w = x2 * x2 * xc;
    const float dielectric = kF0 + (1.f - kF0) * w;
    const Mask has_s = finite(s);
    EvalPdf r;
    for (int c = 0; c < 3; ++c) {
      float v = when(has_d, 0.f + (one_m * scale_d) * q.c[c], 0.f);
      v = when(has_m, v + (q.metallic * scale_m) * q.f_ms[c], v);
      const float f = 0.f + v * b[2];
      const float fresnel = one_m * dielectric + q.metallic * (q.c[c] + (1.f - q.c[c]) * w);
      r.f[c] = when(has_s, f + fresnel * s, f);
    }
    float p = 0.f + (1.f - p_spec) * (b[2] > 0.f ? b[2] * kInvPi : 0.f);
    const float g = d * g1_i / (4.f * a[2]);
    p = when(mask(dot3(b, h) > 0.f) & finite(g), p + p_spec * g, p);
    r.pdf = p;
    zero_below_surface(a, b, &r);
    return r;
  }

  [[gnu::always_inline]] static EvalPdf eval_pdf(const Params& q, const float* a,
                                                 const float* b) {
    const Albedo ai = ggx_albedo(q.tables.ggx_albedo, a[2], q.roughness);
    EvalPdf r = evaluate(q, a, b, ai, specular_probability(q, ai));
    clean_answer(&r);
    return r;
  }

  [[gnu::always_inline]] static Sample sample(const Params& q, const float* a, float u_lobe,
                                              float u0, float u1) {
    const Albedo ai = ggx_albedo(q.tables.ggx_albedo, a[2], q.roughness);
    const float p_spec = specular_probability(q, ai);
    const Mask pick_spec = mask(u_lobe < p_spec);
    // The specular lobe's direction: visible normals, reflect; the base's: cosine-weighted.
    float m[3];
    Ggx::sample_visible(q.alpha, a, u0, u1, m);
    float spec_wo[3], wo[3];
    lane::reflect(a, m, spec_wo);
    cosine_hemisphere(u0, u1, wo);
    Sample r;
    for (int c = 0; c < 3; ++c) r.wo[c] = when(pick_spec, spec_wo[c], wo[c]);
    // One-sample MIS over the lobes: weight = f cos / (mixture pdf) (Veach 1997 ch. 9).
    const EvalPdf e = evaluate(q, a, r.wo, ai, p_spec);
    r.pdf = e.pdf;
    for (int c = 0; c < 3; ++c) r.weight[c] = e.f[c] / e.pdf;
    // MetallicRoughnessBsdf::sample's conditions, then SurfaceBsdf::sample's checks.
    r.ok = ~mask(a[2] <= 0.f) & ~mask(r.wo[2] <= 0.f) & mask(r.pdf > 0.f) & finite(r.pdf) &
           finite(r.weight[0]) & finite(r.weight[1]) & finite(r.weight[2]) & finite(r.wo[0]) &
           finite(r.wo[1]) & finite(r.wo[2]);
    return r;
  }
};

}  // namespace penumbra::lane
