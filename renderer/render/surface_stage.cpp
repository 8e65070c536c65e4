#include "renderer/render/surface_stage.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <iterator>

#include <emmintrin.h>
#include <xmmintrin.h>

#include "renderer/core/simd_clones.h"
#include "renderer/materials/conductor.h"
#include "renderer/materials/dielectric.h"
#include "renderer/materials/diffuse.h"
#include "renderer/materials/metallic_roughness.h"
#include "renderer/materials/microfacet_albedo.h"
#include "renderer/materials/plastic.h"
#include "renderer/render/lane_bsdfs.h"
#include "renderer/sampling/sampling.h"
#include "renderer/textures/image_texture.h"

namespace penumbra {
namespace {

[[gnu::always_inline]] inline uint32_t bits_of(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}
[[gnu::always_inline]] inline float float_of(uint32_t b) {
  float f;
  std::memcpy(&f, &b, sizeof f);
  return f;
}

// One component of offset_ray_origin after p + offset: next_float_up where the offset is
// positive, next_float_down where it is negative (core/ray.h), as selects.
[[gnu::always_inline]] inline float step_away(float po, float offset) {
  const float vu = po == 0.f ? 0.f : po;  // -0 becomes +0 (and +0 stays)
  const uint32_t bu = bits_of(vu);
  const float up = po == kInfinity ? po : float_of(vu >= 0.f ? bu + 1u : bu - 1u);
  const float vd = po == 0.f ? -0.f : po;
  const uint32_t bd = bits_of(vd);
  const float down = po == -kInfinity ? po : float_of(vd > 0.f ? bd - 1u : bd + 1u);
  return offset > 0.f ? up : (offset < 0.f ? down : po);
}

// offset_ray_origin(p, e, n, w) (core/ray.h, pbrt-v4 section 6.8.6).
[[gnu::always_inline]] inline void offset_origin(float px, float py, float pz, float ex, float ey,
                                                 float ez, float nx, float ny, float nz, float wx,
                                                 float wy, float wz, float* ox, float* oy,
                                                 float* oz) {
  const float d = (std::fabs(nx) * ex + std::fabs(ny) * ey) + std::fabs(nz) * ez;
  const bool flip = ((wx * nx + wy * ny) + wz * nz) < 0.f;
  const float fx = d * nx, fy = d * ny, fz = d * nz;
  const float dx = flip ? -fx : fx, dy = flip ? -fy : fy, dz = flip ? -fz : fz;
  *ox = step_away(px + dx, dx);
  *oy = step_away(py + dy, dy);
  *oz = step_away(pz + dz, dz);
}

// path_step_detail::geometry_agrees.
[[gnu::always_inline]] inline Mask agrees(float ax, float ay, float az, float bx, float by,
                                          float bz, float nx, float ny, float nz, float a_z_local,
                                          float b_z_local) {
  const float geo = ((ax * nx + ay * ny) + az * nz) * ((bx * nx + by * ny) + bz * nz);
  const float shade = a_z_local * b_z_local;
  return mask(geo != 0.f) & ~(mask(geo > 0.f) ^ mask(shade > 0.f));
}

// The arrays of a stage's lanes, inputs and results (SurfaceStage's members).
struct Lanes {
  const float *p[3], *e[3], *ng[3], *ns[3], *dir[3], *beta[3];
  const float *colour[3], *alpha, *coat_eta, *spec_weight, *diffuse_scale;
  const float *metallic, *roughness, *e_avg, *dielectric_avg, *f_ms[3];
  const int32_t *table, *nodes;
  lane::Tables tables;
  // Normal-mapped lanes: whether, the tangent frame's s and t (path_step.h tangent_frame; its
  // n is ns) and the mapped normal (SurfaceBsdf::mapped_normal).
  const int32_t* mapped;
  const float *frame_s[3], *frame_t[3], *mapped_n[3];
  const float *time, *eta, *u_lobe, *u_dir[2], *u_rr;
  const int32_t* depth;
  const int32_t *light_ok, *l_delta;
  const float *l_wi[3], *l_distance, *l_pdf, *l_p[3], *l_error[3], *l_n[3], *l_value[3], *l_pmf;
  int32_t *staged, *alive, *has_shadow, *nee_ray, *dims, *prev_delta;
  float *s_origin[3], *s_dir[3], *s_t_max, *s_contrib[3];
  float *origin[3], *wo[3], *beta_out[3], *prev_pdf, *eta_out;
};

// Frame(n) on one lane: Duff et al. 2017 (core/frame.h), its operations in order.
[[gnu::always_inline]] inline void duff_frame(float nx, float ny, float nz, float* s, float* t) {
  const float sign = std::copysign(1.f, nz);
  const float a = -1.f / (sign + nz);
  const float b = nx * ny * a;
  s[0] = 1.f + sign * nx * nx * a;
  s[1] = sign * b;
  s[2] = -sign * nx;
  t[0] = b;
  t[1] = sign + ny * ny * a;
  t[2] = -ny;
}

// SurfaceBsdf's normal map (materials/surface_bsdf.cpp) on one lane: the perturbed frame of
// mapped normal m for the (front-mirrored) direction a, and the shadow terminator.
struct PerturbedFrame {
  float s[3], t[3], n[3];
};
[[gnu::always_inline]] inline PerturbedFrame perturbed_frame(const float* m, const float* a) {
  // Mirrored about the unperturbed normal where it faces away from a.
  const Mask away = mask(a[2] * lane::dot3(a, m) <= 0.f);
  float n[3] = {when(away, -m[0], m[0]), when(away, -m[1], m[1]), m[2]};
  const float len = std::sqrt(lane::dot3(n, n));
  const Mask some = mask(len > 1e-6f);
  for (int c = 0; c < 3; ++c) n[c] = when(some, n[c] / len, c == 2 ? 1.f : 0.f);
  // Mitsuba's tangent: +x made orthogonal to n; Frame(n) (Duff et al. 2017) where it degenerates.
  const float r[3] = {1.f - n[0] * n[0], 0.f - n[1] * n[0], 0.f - n[2] * n[0]};
  const float ls = std::sqrt(lane::dot3(r, r));
  const Mask tangent = mask(ls > 1e-6f);
  float ds[3], dt[3];
  duff_frame(n[0], n[1], n[2], ds, dt);
  const float ts[3] = {r[0] / ls, r[1] / ls, r[2] / ls};
  // glm::cross(n, ts).
  const float tt[3] = {n[1] * ts[2] - ts[1] * n[2], n[2] * ts[0] - ts[2] * n[0],
                       n[0] * ts[1] - ts[0] * n[1]};
  PerturbedFrame f;
  for (int c = 0; c < 3; ++c) {
    f.n[c] = n[c];
    f.s[c] = when(tangent, ts[c], ds[c]);
    f.t[c] = when(tangent, tt[c], dt[c]);
  }
  return f;
}
// tan^2 of v's angle to +z: max(0, 1 - c^2) / c^2.
[[gnu::always_inline]] inline float tan2_theta(const float* v) {
  const float c2 = v[2] * v[2];
  const float s2 = 1.f - c2;
  return (0.f < s2 ? s2 : 0.f) / c2;
}
// shadow_terminator (Estevez et al. 2019, eq. 3-4) of perturbed normal n towards v.
[[gnu::always_inline]] inline float shadow_terminator(const float* n, const float* v) {
  const float x = 0.125f * tan2_theta(n);
  const float alpha2 = 1.f < x ? 1.f : x;
  const float g = 2.f / (1.f + std::sqrt(1.f + alpha2 * tan2_theta(v)));
  return when(mask(alpha2 > 0.f), g, 1.f);
}
// Frame::to_local and to_world.
[[gnu::always_inline]] inline void to_local(const PerturbedFrame& f, const float* v, float* out) {
  out[0] = lane::dot3(v, f.s);
  out[1] = lane::dot3(v, f.t);
  out[2] = lane::dot3(v, f.n);
}
[[gnu::always_inline]] inline void to_world(const PerturbedFrame& f, const float* v, float* out) {
  for (int c = 0; c < 3; ++c) out[c] = (f.s[c] * v[0] + f.t[c] * v[1]) + f.n[c] * v[2];
}

// path_scatter of the path integrator on a `Model` (lane_bsdfs.h), lane by lane (see the
// header). `next_event`: whether the step samples a light; `kMapped`: whether some lanes are
// normal-mapped (SurfaceBsdf's evaluate_mapped and sample_mapped in the perturbed frame).
template <class Model, bool kNextEvent, bool kMapped>
[[gnu::always_inline]] inline void surface_step(const Lanes& lanes, size_t n, int32_t rr_depth) {
  // A local copy: stores through the result pointers cannot then change the pointers, which
  // GCC would otherwise reload every iteration (and not vectorise).
  const Lanes L = lanes;
  constexpr float kShadowScale = 1.f - kShadowEpsilon;
  // The result arrays never overlap the inputs, which GCC cannot prove for pointers in a struct.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
  for (size_t i = 0; i < n; ++i) {
    const float px = L.p[0][i], py = L.p[1][i], pz = L.p[2][i];
    const float ex = L.e[0][i], ey = L.e[1][i], ez = L.e[2][i];
    const float gx = L.ng[0][i], gy = L.ng[1][i], gz = L.ng[2][i];
    const float nx = L.ns[0][i], ny = L.ns[1][i], nz = L.ns[2][i];
    const float bx = L.beta[0][i], by = L.beta[1][i], bz = L.beta[2][i];
    const lane::Params q{{L.colour[0][i], L.colour[1][i], L.colour[2][i]},
                         L.alpha[i],
                         L.coat_eta[i],
                         L.spec_weight[i],
                         L.diffuse_scale[i],
                         L.table[i],
                         L.nodes[i],
                         L.tables,
                         L.metallic[i],
                         L.roughness[i],
                         L.e_avg[i],
                         L.dielectric_avg[i],
                         {L.f_ms[0][i], L.f_ms[1][i], L.f_ms[2][i]}};
    // Frame(ns).
    float fs[3], ft[3];
    duff_frame(nx, ny, nz, fs, ft);
    float sx = fs[0], sy = fs[1], sz = fs[2];
    float tx = ft[0], ty = ft[1], tz = ft[2];
    // A normal-mapped surface's frame follows dp/du (tangent_frame, computed in add_many).
    const Mask mapped = kMapped ? L.mapped[i] : 0;
    if constexpr (kMapped) {
      sx = when(mapped, L.frame_s[0][i], sx);
      sy = when(mapped, L.frame_s[1][i], sy);
      sz = when(mapped, L.frame_s[2][i], sz);
      tx = when(mapped, L.frame_t[0][i], tx);
      ty = when(mapped, L.frame_t[1][i], ty);
      tz = when(mapped, L.frame_t[2][i], tz);
    }
    // wi = -direction, in world and local coordinates (Frame::to_local).
    const float wx = -L.dir[0][i], wy = -L.dir[1][i], wz = -L.dir[2][i];
    const float wi_x = (wx * sx + wy * sy) + wz * sz;
    const float wi_y = (wx * tx + wy * ty) + wz * tz;
    const float wi_z = (wx * nx + wy * ny) + wz * nz;
    // SurfaceBsdf: a two-sided model seen from the back is its front, mirrored.
    const Mask flip = Model::kTwoSided ? mask(wi_z < 0.f) : 0;
    const float a[3] = {wi_x, wi_y, when(flip, -wi_z, wi_z)};

    // Next-event estimation.
    const float lx = L.l_wi[0][i], ly = L.l_wi[1][i], lz = L.l_wi[2][i];
    const float l_pdf = L.l_pdf[i] * L.l_pmf[i];
    const float lo_x = (lx * sx + ly * sy) + lz * sz;
    const float lo_y = (lx * tx + ly * ty) + lz * tz;
    const float lo_z = (lx * nx + ly * ny) + lz * nz;
    const Mask l_agrees = agrees(wx, wy, wz, lx, ly, lz, gx, gy, gz, wi_z, lo_z);
    const float b[3] = {lo_x, lo_y, when(flip, -lo_z, lo_z)};
    // A normal-mapped lane's model answers in the perturbed frame P of a (evaluate_mapped: zero
    // unless b lies on the same side of P as of the surface; the value times the terminator).
    PerturbedFrame pf;
    float a_in[3] = {a[0], a[1], a[2]}, b_in[3] = {b[0], b[1], b[2]};
    if constexpr (kMapped) {
      const float mn[3] = {L.mapped_n[0][i], L.mapped_n[1][i], L.mapped_n[2][i]};
      pf = perturbed_frame(mn, a);
      float ap[3], bp[3];
      to_local(pf, a, ap);
      to_local(pf, b, bp);
      for (int c = 0; c < 3; ++c) {
        a_in[c] = when(mapped, ap[c], a[c]);
        b_in[c] = when(mapped, bp[c], b[c]);
      }
    }
    lane::EvalPdf e = Model::eval_pdf(q, a_in, b_in);
    if constexpr (kMapped) {
      const Mask side = mask(b[2] * b_in[2] > 0.f);
      const float term = shadow_terminator(pf.n, b);
      for (int c = 0; c < 3; ++c) e.f[c] = when(mapped, when(side, e.f[c] * term, 0.f), e.f[c]);
      e.pdf = when(mapped & ~side, 0.f, e.pdf);
    }
    // power_heuristic(l_pdf, e.pdf), or 1 for a delta light (path_scatter takes eval alone,
    // whose value is eval_pdf's).
    const float h_a = l_pdf * l_pdf, h_b = e.pdf * e.pdf;
    const float h_ratio = h_a / (h_a + h_b);
    const float mis = L.l_delta[i] != 0 ? 1.f : (h_a + h_b > 0.f ? h_ratio : 0.f);
    const float f_x = e.f[0] * mis, f_y = e.f[1] * mis, f_z = e.f[2] * mis;
    const Mask black = mask(f_x == 0.f) & mask(f_y == 0.f) & mask(f_z == 0.f);
    const Mask nee = mask(kNextEvent) & mask(L.light_ok[i] != 0) & l_agrees & ~black;
    // The shadow ray: from the offset hit point to the light point offset off the light.
    float so_x, so_y, so_z;
    offset_origin(px, py, pz, ex, ey, ez, gx, gy, gz, lx, ly, lz, &so_x, &so_y, &so_z);
    const float lnx = L.l_n[0][i], lny = L.l_n[1][i], lnz = L.l_n[2][i];
    const Mask point = mask(lnx == 0.f) & mask(lny == 0.f) & mask(lnz == 0.f);
    float tg_x, tg_y, tg_z;
    offset_origin(L.l_p[0][i], L.l_p[1][i], L.l_p[2][i], L.l_error[0][i], L.l_error[1][i],
                  L.l_error[2][i], lnx, lny, lnz, -lx, -ly, -lz, &tg_x, &tg_y, &tg_z);
    tg_x = when(point, L.l_p[0][i], tg_x);
    tg_y = when(point, L.l_p[1][i], tg_y);
    tg_z = when(point, L.l_p[2][i], tg_z);
    const float dx = tg_x - so_x, dy = tg_y - so_y, dz = tg_z - so_z;
    const float dist = std::sqrt((dx * dx + dy * dy) + dz * dz);
    const float qx = dx / dist, qy = dy / dist, qz = dz / dist;
    const Mask far_end = lane::finite(L.l_distance[i]);
    const Mask positive = mask(dist > 0.f);
    const float t_max = when(far_end, when(point, dist, dist * kShadowScale), kInfinity);
    L.s_origin[0][i] = so_x;
    L.s_origin[1][i] = so_y;
    L.s_origin[2][i] = so_z;
    L.s_dir[0][i] = when(far_end & positive, qx, lx);
    L.s_dir[1][i] = when(far_end & positive, qy, ly);
    L.s_dir[2][i] = when(far_end & positive, qz, lz);
    L.s_t_max[i] = t_max;
    L.s_contrib[0][i] = bx * f_x * L.l_value[0][i] / l_pdf;
    L.s_contrib[1][i] = by * f_y * L.l_value[1][i] / l_pdf;
    L.s_contrib[2][i] = bz * f_z * L.l_value[2][i] / l_pdf;
    L.nee_ray[i] = nee;
    L.has_shadow[i] = nee & mask(t_max > 0.f);

    // The BSDF's sample, its direction mirrored back to the side wi came from.
    lane::Sample bs = Model::sample(q, a_in, L.u_lobe[i], L.u_dir[0][i], L.u_dir[1][i]);
    if constexpr (kMapped) {
      // sample_mapped: the direction back out of P, on the same side of both; the weight times
      // the terminator; then SurfaceBsdf::sample's finiteness checks.
      float w[3];
      to_world(pf, bs.wo, w);
      const float term = shadow_terminator(pf.n, w);
      const float weight[3] = {bs.weight[0] * term, bs.weight[1] * term, bs.weight[2] * term};
      const Mask ok = bs.ok & mask(w[2] * bs.wo[2] > 0.f) & lane::finite(weight[0]) &
                      lane::finite(weight[1]) & lane::finite(weight[2]) & lane::finite(bs.pdf) &
                      lane::finite(w[0]) & lane::finite(w[1]) & lane::finite(w[2]);
      for (int c = 0; c < 3; ++c) {
        bs.wo[c] = when(mapped, w[c], bs.wo[c]);
        bs.weight[c] = when(mapped, weight[c], bs.weight[c]);
      }
      bs.ok = when(mapped, ok, bs.ok);
    }
    const float wo_z = when(flip, -bs.wo[2], bs.wo[2]);
    const float ww_x = (sx * bs.wo[0] + tx * bs.wo[1]) + nx * wo_z;
    const float ww_y = (sy * bs.wo[0] + ty * bs.wo[1]) + ny * wo_z;
    const float ww_z = (sz * bs.wo[0] + tz * bs.wo[1]) + nz * wo_z;
    const Mask o_agrees = agrees(wx, wy, wz, ww_x, ww_y, ww_z, gx, gy, gz, wi_z, wo_z);
    const float nb_x = bx * bs.weight[0], nb_y = by * bs.weight[1], nb_z = bz * bs.weight[2];
    float o_x, o_y, o_z;
    offset_origin(px, py, pz, ex, ey, ez, gx, gy, gz, ww_x, ww_y, ww_z, &o_x, &o_y, &o_z);
    // max_component (std::max as its comparison), then Russian roulette as path_scatter.
    const float m_yz = nb_y < nb_z ? nb_z : nb_y;
    const float beta_max = nb_x < m_yz ? m_yz : nb_x;
    const Mask roulette = mask(L.depth[i] >= rr_depth);
    const float eta = L.eta[i] * bs.eta;
    const float q_raw = beta_max * eta * eta;
    const float q_rr = 0.95f < q_raw ? 0.95f : q_raw;
    const Mask killed = roulette & mask(L.u_rr[i] >= q_rr);
    L.beta_out[0][i] = when(roulette, nb_x / q_rr, nb_x);
    L.beta_out[1][i] = when(roulette, nb_y / q_rr, nb_y);
    L.beta_out[2][i] = when(roulette, nb_z / q_rr, nb_z);
    L.alive[i] = bs.ok & o_agrees & mask(beta_max > 0.f) & ~killed;
    L.dims[i] = (kNextEvent ? 4 : 2) + (roulette & 1);
    L.origin[0][i] = o_x;
    L.origin[1][i] = o_y;
    L.origin[2][i] = o_z;
    L.wo[0][i] = ww_x;
    L.wo[1][i] = ww_y;
    L.wo[2][i] = ww_z;
    L.prev_pdf[i] = bs.pdf;
    L.prev_delta[i] = bs.delta;
    L.eta_out[i] = eta;
    L.staged[i] = L.staged[i] & e.exact & bs.exact;
  }
}

// The loop compiled for each model and case (a flag inside the loop kept GCC from vectorising
// it).
template <class Model>
[[gnu::always_inline]] inline void step_cases(const Lanes& lanes, size_t n, bool next_event,
                                              bool mapped, int32_t rr_depth) {
  if (next_event && !Model::kDeltaOnly) {
    if (mapped)
      surface_step<Model, true, true>(lanes, n, rr_depth);
    else
      surface_step<Model, true, false>(lanes, n, rr_depth);
  } else {
    if (mapped)
      surface_step<Model, false, true>(lanes, n, rr_depth);
    else
      surface_step<Model, false, false>(lanes, n, rr_depth);
  }
}
PENUMBRA_SIMD_CLONES
void lambert_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                         int32_t rr_depth) {
  step_cases<lane::Lambert>(lanes, n, next_event, mapped, rr_depth);
}
PENUMBRA_SIMD_CLONES
void rough_conductor_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                                 int32_t rr_depth) {
  step_cases<lane::RoughConductor>(lanes, n, next_event, mapped, rr_depth);
}
PENUMBRA_SIMD_CLONES
void smooth_plastic_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                                int32_t rr_depth) {
  step_cases<lane::SmoothPlastic>(lanes, n, next_event, mapped, rr_depth);
}
PENUMBRA_SIMD_CLONES
void rough_plastic_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                               int32_t rr_depth) {
  step_cases<lane::RoughPlastic>(lanes, n, next_event, mapped, rr_depth);
}
PENUMBRA_SIMD_CLONES
void smooth_conductor_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                                  int32_t rr_depth) {
  step_cases<lane::SmoothConductor>(lanes, n, next_event, mapped, rr_depth);
}
PENUMBRA_SIMD_CLONES
void smooth_dielectric_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                                   int32_t rr_depth) {
  step_cases<lane::SmoothDielectric>(lanes, n, next_event, mapped, rr_depth);
}
PENUMBRA_SIMD_CLONES
void rough_dielectric_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                                  int32_t rr_depth) {
  step_cases<lane::RoughDielectric>(lanes, n, next_event, mapped, rr_depth);
}
// Without partial redundancy elimination: GCC's PRE turned this model's zero tests (evaluate's
// wi.z <= 0 or wo.z <= 0, sample's own) into selects between booleans of different widths,
// which its vectoriser refuses, and the loop stayed scalar (no ymm instruction in any clone).
#if defined(__GNUC__) && !defined(__clang__)
#define PENUMBRA_NO_TREE_PRE __attribute__((optimize("no-tree-pre")))
#else
#define PENUMBRA_NO_TREE_PRE
#endif
PENUMBRA_SIMD_CLONES PENUMBRA_NO_TREE_PRE
void metallic_roughness_step_kernel(const Lanes& lanes, size_t n, bool next_event, bool mapped,
                                    int32_t rr_depth) {
  step_cases<lane::MetallicRoughness>(lanes, n, next_event, mapped, rr_depth);
}

}  // namespace

bool SurfaceStage::fill_params(const SurfaceBsdf& b, SurfaceParams* q) const {
  const BsdfModel& bsdf = b.model();
  if (model_ == StageModel::kRoughDielectric || model_ == StageModel::kSmoothDielectric) {
    // (The scene's transmission feature is what has path_scatter update eta; a dielectric
    // implies it.)
    const auto* dielectric = std::get_if<DielectricBsdf>(&bsdf);
    if (!dielectric || dielectric->smooth() != (model_ == StageModel::kSmoothDielectric) ||
        dielectric->index_matched() || !scene_.features().transmission)
      return false;
    q->colour = Spectrum(1.f);
    q->alpha = dielectric->alpha();
    q->eta = dielectric->ior();
  } else if (!b.two_sided()) {
    return false;
  } else if (model_ == StageModel::kMetallicRoughness) {
    const auto* mr = std::get_if<MetallicRoughnessBsdf>(&bsdf);
    if (!mr || mr->smooth()) return false;
    q->colour = mr->albedo();
    q->alpha = mr->alpha();
    q->metallic = mr->metallic();
    q->roughness = mr->roughness();
    q->e_avg = mr->e_avg();
    q->dielectric_avg = mr->dielectric_avg();
    q->f_ms = mr->f_ms();
    if (!is_finite(q->f_ms)) return false;
  } else if (model_ == StageModel::kLambert) {
    const auto* diffuse = std::get_if<DiffuseBsdf>(&bsdf);
    if (!diffuse) return false;
    q->colour = diffuse->albedo();
  } else if (model_ == StageModel::kRoughConductor || model_ == StageModel::kSmoothConductor) {
    const auto* conductor = std::get_if<ConductorBsdf>(&bsdf);
    if (!conductor || conductor->smooth() != (model_ == StageModel::kSmoothConductor)) return false;
    q->colour = conductor->albedo();
    q->alpha = conductor->alpha();
  } else {
    const auto* plastic = std::get_if<PlasticBsdf>(&bsdf);
    if (!plastic || plastic->smooth() != (model_ == StageModel::kSmoothPlastic)) return false;
    q->colour = plastic->albedo();
    q->alpha = plastic->alpha();
    q->eta = plastic->eta();
    q->spec_weight = plastic->specular_sampling_weight();
    q->diffuse_scale = plastic->diffuse_scale();
    if (model_ == StageModel::kRoughPlastic) {
      const CoatingTables& t = plastic->tables();
      if (!t.square_nodes) return false;  // adaptive nodes (ior < 1): bisection, left to the scalar step
      size_t k = 0;
      while (k < tables_.size() && tables_[k] != &t) ++k;
      // A textured plastic keeps its coating's tables (only the colour varies), so a lookup
      // at a hit finds them among those its material's own BSDF added here.
      if (k == tables_.size()) return false;
      q->table = int32_t(k * kCoatingTableCapacity);
      q->nodes = t.nodes;
    }
  }
  return is_finite(q->colour);
}

SurfaceStage::SurfaceStage(const Scene& scene, StageModel model)
    : scene_(scene),
      model_(model),
      lights_(scene),
      quad_rows_(lights_.quad_table, StagedLights::kQuadRow, StagedLights::kQuad),
      sphere_rows_(lights_.sphere_table, StagedLights::kSphereRow, StagedLights::kSphere),
      point_rows_(lights_.point_table, StagedLights::kPointRow, StagedLights::kPoint) {
  params_of_.assign(scene.object_count(), -1);
  textured_of_.assign(scene.object_count(), 0);
  texture_lookups_of_.assign(scene.object_count(), -1);
  normal_lookups_of_.assign(scene.object_count(), -1);
  for (size_t o = 0; o < scene.object_count(); ++o) {
    const Material& m = scene.material(scene.object(uint32_t(o)).material);
    // A rough plastic's coating tables join the stage's list the first time a surface uses them.
    if (model == StageModel::kRoughPlastic)
      if (const auto* plastic = std::get_if<PlasticBsdf>(&m.bsdf().model());
          plastic && plastic->tables().square_nodes &&
          std::find(tables_.begin(), tables_.end(), &plastic->tables()) == tables_.end()) {
        const CoatingTables& t = plastic->tables();
        tables_.push_back(&t);
        table_cosines_.insert(table_cosines_.end(), t.cosines.begin(), t.cosines.end());
        table_values_.insert(table_values_.end(), t.transmittance.begin(), t.transmittance.end());
      }
    // A textured material's parameters are looked up at each hit (add_many); its own BSDF, built
    // from the textures' factors, has the model its hits have (a textured roughness that
    // reaches zero makes a hit's lobe smooth: add_many leaves that hit to path_scatter).
    SurfaceParams q;
    if (!fill_params(m.bsdf(), &q)) continue;
    params_of_[o] = int32_t(params_.size());
    textured_of_[o] = m.varies();  // (a normal map makes a material vary)
    params_.push_back(q);
    const bool roughness_model =
        model == StageModel::kRoughConductor || model == StageModel::kSmoothConductor ||
        model == StageModel::kRoughDielectric || model == StageModel::kSmoothDielectric;
    if (m.color_image())
      texture_lookups_of_[o] = lookups_for(m, TextureLookups::kColour);
    else if (m.roughness_image() && roughness_model)
      texture_lookups_of_[o] = lookups_for(m, TextureLookups::kRoughness);
    else if (m.varies() && !m.only_normal_varies())
      texture_lookups_of_[o] = lookups_for(m, TextureLookups::kParameters);
    if (m.normal_mapped()) normal_lookups_of_[o] = lookups_for(m, TextureLookups::kNormal);
  }
  if (model == StageModel::kMetallicRoughness) albedo_table_ = ggx_albedo_table();
}

int32_t SurfaceStage::lookups_for(const Material& m, TextureLookups::Kind kind) {
  size_t k = 0;
  while (k < texture_lookups_.size() &&
         (texture_lookups_[k].material != &m || texture_lookups_[k].kind != kind))
    ++k;
  if (k == texture_lookups_.size())
    texture_lookups_.push_back(TextureLookups{&m, kind, {}, {}, {}, {}});
  return int32_t(k);
}

void SurfaceStage::start(size_t paths) {
  count_ = 0;
  unfit_.clear();
  own_code_lanes_.clear();
  emission_lanes_.clear();
  mapped_lanes_.clear();
  for (TextureLookups& l : texture_lookups_) {
    l.lanes.clear();
    l.u.clear();
    l.v.clear();
    l.params.clear();
  }
  if (slot_.size() >= paths) return;
  slot_.resize(paths);
  for (int c = 0; c < 3; ++c)
    for (auto* a : {&p_[c], &p_error_[c], &ng_[c], &ns_[c], &dir_[c], &beta_[c], &colour_[c],
                    &l_wi_[c], &l_p_[c], &l_error_[c], &l_n_[c], &l_value_[c], &s_origin_[c],
                    &s_dir_[c], &s_contrib_[c], &origin_[c], &wo_[c], &beta_out_[c],
                    &frame_s_[c], &frame_t_[c], &mapped_n_[c], &f_ms_[c]})
      a->resize(paths);
  for (auto* a : {&alpha_, &coat_eta_, &spec_weight_, &diffuse_scale_, &metallic_, &roughness_,
                  &e_avg_, &dielectric_avg_, &time_, &eta_, &u_light_,
                  &u_point_[0], &u_point_[1], &u_lobe_, &u_dir_[0], &u_dir_[1], &u_rr_,
                  &l_distance_, &l_pdf_, &l_pmf_, &s_t_max_, &prev_pdf_, &eta_out_})
    a->resize(paths);
  for (auto* a : {&table_, &nodes_, &depth_, &light_, &light_ok_, &l_delta_, &staged_, &alive_,
                  &has_shadow_, &nee_ray_, &dims_, &prev_delta_, &mapped_})
    a->resize(paths);
}

void SurfaceStage::write_params(size_t i, const SurfaceParams& q) {
  for (int c = 0; c < 3; ++c) colour_[c][i] = q.colour[c];
  // (Each model reads only its own constants: a Lambertian surface's colour alone.)
  if (model_ != StageModel::kLambert) {
    alpha_[i] = q.alpha;
    coat_eta_[i] = q.eta;
    spec_weight_[i] = q.spec_weight;
    diffuse_scale_[i] = q.diffuse_scale;
    table_[i] = q.table;
    nodes_[i] = q.nodes;
  }
  if (model_ == StageModel::kMetallicRoughness) {
    metallic_[i] = q.metallic;
    roughness_[i] = q.roughness;
    e_avg_[i] = q.e_avg;
    dielectric_avg_[i] = q.dielectric_avg;
    for (int c = 0; c < 3; ++c) f_ms_[c][i] = q.f_ms[c];
  }
}

void SurfaceStage::add_textured(size_t i, const PathState& s, const SurfaceHit& hit) {
  // path_scatter's lookup, at the same point: the same parameters to the bit.
  const Material& m = scene_.material(scene_.object(hit.object).material);
  auto defer = [&](int32_t k) {  // look up at (u, v) with the list's other hits
    TextureLookups& l = texture_lookups_[size_t(k)];
    l.lanes.push_back(uint32_t(i));
    l.u.push_back(hit.uv.x);
    l.v.push_back(hit.uv.y);
  };
  // The object's parameters now; a textured parameter's texel looked up with the other hits on
  // the material's images (look_up_textures): bsdf_at is bsdf() with the texture's colour or
  // roughness, or (kParameters) the BSDF of all its parameter textures' texels. Where only the
  // normal map varies, bsdf_at is bsdf() with the map's normal: no list but the normal's.
  write_params(i, params_[size_t(params_of_[hit.object])]);
  if (const int32_t k = texture_lookups_of_[hit.object]; k >= 0) {
    defer(k);
    TextureLookups& l = texture_lookups_[size_t(k)];
    if (l.kind == TextureLookups::kParameters) l.params.push_back(params_of_[hit.object]);
  }
  if (!m.normal_mapped()) return;
  // path_scatter's frame for a normal map, along dp/du (its n is the hit's ns).
  SurfaceHit h = hit;
  const Frame f = path_step_detail::tangent_frame(scene_, s.ray.time, &h);
  mapped_lanes_.push_back(uint32_t(i));
  for (int c = 0; c < 3; ++c) {
    frame_s_[c][i] = f.s[c];
    frame_t_[c][i] = f.t[c];
  }
  // The map's normal, looked up with the other hits on it.
  defer(normal_lookups_of_[hit.object]);
}

void SurfaceStage::add_many(size_t n, const uint32_t* slots, const uint32_t* live,
                            const uint32_t* hit_of, const PathState* states,
                            const SurfaceHit* hits, const float* x, const float* y,
                            const float* z, size_t stride, bool next_event) {
  // Field group by field group, a loop each over the chunk the driver hands in (a call per path
  // cost a tenth of a Cornell box render: docs/performance.md, levers, session 35).
  const size_t base = count_;
  count_ += n;
  uint32_t* __restrict slot = slot_.data() + base;
  for (size_t i = 0; i < n; ++i) slot[i] = slots[i];
  for (size_t i = 0; i < n; ++i) {
    const SurfaceHit& hit = hits[slots[i]];
    if (textured_of_[hit.object])
      add_textured(base + i, states[live[slots[i]]], hit);
    else
      write_params(base + i, params_[size_t(params_of_[hit.object])]);
  }
  // The hits' points, error bounds and normals and the paths' directions, throughputs, times,
  // etas and depths into the lanes' arrays.
  float* __restrict const hit_rows[12] = {
      p_[0].data() + base,  p_[1].data() + base,       p_[2].data() + base,
      p_error_[0].data() + base, p_error_[1].data() + base, p_error_[2].data() + base,
      ng_[0].data() + base, ng_[1].data() + base,      ng_[2].data() + base,
      ns_[0].data() + base, ns_[1].data() + base,      ns_[2].data() + base};
  float* __restrict dx = dir_[0].data() + base;
  float* __restrict dy = dir_[1].data() + base;
  float* __restrict dz = dir_[2].data() + base;
  float* __restrict bx = beta_[0].data() + base;
  float* __restrict by = beta_[1].data() + base;
  float* __restrict bz = beta_[2].data() + base;
  float* __restrict time = time_.data() + base;
  float* __restrict eta = eta_.data() + base;
  int32_t* __restrict depth = depth_.data() + base;
  size_t i = 0;
#if defined(__SSE2__)
  // Four lanes at a time as 4x4 transposes (SSE2, every x86-64 CPU): a hit's twelve floats
  // from p to ns are three 16-byte loads, a path's nine fields three more, and each array gets
  // one 16-byte store per four lanes, instead of a scalar load and store per field and lane.
  static_assert(offsetof(SurfaceHit, p) == 4 && offsetof(SurfaceHit, p_error) == 16 &&
                    offsetof(SurfaceHit, ng) == 28 && offsetof(SurfaceHit, ns) == 40,
                "SurfaceHit's layout, as the transposes read it");
  static_assert(offsetof(PathState, ray) == 0 && offsetof(Ray, direction) == 12 &&
                    offsetof(Ray, time) == 24 && offsetof(PathState, beta) == 44 &&
                    offsetof(PathState, eta) == 76 && offsetof(PathState, depth) == 80 &&
                    sizeof(PathState) == 96,
                "PathState's layout, as the transposes read it");
  for (; i + 4 <= n; i += 4) {
    __m128 h[3][4], d[4], b[4], e[4];
    for (int j = 0; j < 4; ++j) {
      const uint32_t k = slots[i + size_t(j)];
      const float* f = &hits[k].p.x;
      h[0][j] = _mm_loadu_ps(f);      // p.x p.y p.z e.x
      h[1][j] = _mm_loadu_ps(f + 4);  // e.y e.z ng.x ng.y
      h[2][j] = _mm_loadu_ps(f + 8);  // ng.z ns.x ns.y ns.z
      const float* g = reinterpret_cast<const float*>(&states[live[k]]);
      d[j] = _mm_loadu_ps(g + 3);   // direction, time
      b[j] = _mm_loadu_ps(g + 10);  // radiance.z, beta
      e[j] = _mm_loadu_ps(g + 17);  // prev_p.y, prev_p.z, eta, depth
    }
    for (int r = 0; r < 3; ++r) {
      _MM_TRANSPOSE4_PS(h[r][0], h[r][1], h[r][2], h[r][3]);
      for (int c = 0; c < 4; ++c) _mm_storeu_ps(hit_rows[4 * r + c] + i, h[r][c]);
    }
    _MM_TRANSPOSE4_PS(d[0], d[1], d[2], d[3]);
    _MM_TRANSPOSE4_PS(b[0], b[1], b[2], b[3]);
    _MM_TRANSPOSE4_PS(e[0], e[1], e[2], e[3]);
    _mm_storeu_ps(dx + i, d[0]);
    _mm_storeu_ps(dy + i, d[1]);
    _mm_storeu_ps(dz + i, d[2]);
    _mm_storeu_ps(time + i, d[3]);
    _mm_storeu_ps(bx + i, b[1]);
    _mm_storeu_ps(by + i, b[2]);
    _mm_storeu_ps(bz + i, b[3]);
    _mm_storeu_ps(eta + i, e[2]);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(depth + i), _mm_castps_si128(e[3]));
  }
#endif
  for (; i < n; ++i) {
    const SurfaceHit& hit = hits[slots[i]];
    for (int c = 0; c < 3; ++c) {
      hit_rows[c][i] = hit.p[c];
      hit_rows[3 + c][i] = hit.p_error[c];
      hit_rows[6 + c][i] = hit.ng[c];
      hit_rows[9 + c][i] = hit.ns[c];
    }
    const PathState& s = states[live[slots[i]]];
    dx[i] = s.ray.direction.x;
    dy[i] = s.ray.direction.y;
    dz[i] = s.ray.direction.z;
    bx[i] = s.beta.x;
    by[i] = s.beta.y;
    bz[i] = s.beta.z;
    time[i] = s.ray.time;
    eta[i] = s.eta;
    depth[i] = s.depth;
  }
  // The step's values in the order path_scatter takes them: light choice and point (with next-
  // event estimation; one get_1d_2d pair), lobe and direction (the next pair), roulette.
  const size_t d = estimates_light(next_event) ? 2 : 0;
  const float* __restrict light_z = z;
  const float* __restrict point_x = x + stride;
  const float* __restrict point_y = y + stride;
  const float* __restrict lobe_z = z + d / 2 * stride;
  const float* __restrict dir_x = x + (d + 1) * stride;
  const float* __restrict dir_y = y + (d + 1) * stride;
  const float* __restrict rr_x = x + (d + 2) * stride;
  float* __restrict u_light = u_light_.data() + base;
  float* __restrict u_point_x = u_point_[0].data() + base;
  float* __restrict u_point_y = u_point_[1].data() + base;
  float* __restrict u_lobe = u_lobe_.data() + base;
  float* __restrict u_dir_x = u_dir_[0].data() + base;
  float* __restrict u_dir_y = u_dir_[1].data() + base;
  float* __restrict u_rr = u_rr_.data() + base;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = hit_of[slots[i]];
    u_light[i] = light_z[j];
    u_point_x[i] = point_x[j];
    u_point_y[i] = point_y[j];
    u_lobe[i] = lobe_z[j];
    u_dir_x[i] = dir_x[j];
    u_dir_y[i] = dir_y[j];
    u_rr[i] = rr_x[j];
  }
}

void SurfaceStage::look_up_textures() {
  const bool smooth_model =
      model_ == StageModel::kSmoothConductor || model_ == StageModel::kSmoothDielectric;
  for (const TextureLookups& l : texture_lookups_) {
    const size_t n = l.lanes.size();
    if (n == 0) continue;
    for (auto& a : looked_up_)
      if (a.size() < n) a.resize(n);
    if (l.kind == TextureLookups::kNormal) {
      l.material->normal_image()->eval_many(n, l.u.data(), l.v.data(), looked_up_[0].data(),
                                            looked_up_[1].data(), looked_up_[2].data());
      for (size_t j = 0; j < n; ++j) {
        // Material::mapped_normal_at on the looked-up texel.
        const vec3 normal = l.material->normal_of_texel(
            Spectrum(looked_up_[0][j], looked_up_[1][j], looked_up_[2][j]));
        for (int k = 0; k < 3; ++k) mapped_n_[k][l.lanes[j]] = normal[k];
      }
      continue;
    }
    if (l.kind == TextureLookups::kParameters) {
      // bsdf_at without the normal (which its own list looks up): the BSDF of the hit's texels,
      // taken apart as add_many takes apart a BSDF (fill_params), a hit whose BSDF leaves the model
      // (a smooth texel) left to path_scatter.
      const Material& m = *l.material;
      const ImageSpectrumTexture* colour = m.color_texture();
      const ImageFloatTexture* roughness = m.roughness_texture();
      const ImageFloatTexture* metallic = m.metallic_texture();
      if (colour)
        colour->eval_many(n, l.u.data(), l.v.data(), looked_up_[0].data(), looked_up_[1].data(),
                          looked_up_[2].data());
      if (roughness) {
        if (looked_up_roughness_.size() < n) looked_up_roughness_.resize(n);
        roughness->eval_many(n, l.u.data(), l.v.data(), looked_up_roughness_.data());
      }
      if (metallic) {
        if (looked_up_metallic_.size() < n) looked_up_metallic_.resize(n);
        metallic->eval_many(n, l.u.data(), l.v.data(), looked_up_metallic_.data());
      }
      for (size_t j = 0; j < n; ++j) {
        const SurfaceBsdf b = m.bsdf_of_texels(
            colour ? Spectrum(looked_up_[0][j], looked_up_[1][j], looked_up_[2][j]) : Spectrum(0.f),
            roughness ? looked_up_roughness_[j] : 0.f, metallic ? looked_up_metallic_[j] : 0.f);
        const uint32_t i = l.lanes[j];
        SurfaceParams q = params_[size_t(l.params[j])];
        if (!fill_params(b, &q)) unfit_.push_back(i);
        write_params(i, q);
      }
      continue;
    }
    if (l.kind == TextureLookups::kRoughness) {
      l.material->roughness_image()->eval_many(n, l.u.data(), l.v.data(), looked_up_[0].data());
      for (size_t j = 0; j < n; ++j) {
        // The model's constructor on the looked-up roughness (ConductorBsdf, DielectricBsdf):
        // smooth below the least alpha, else GGX with alpha clamped to it; a hit whose lobe is
        // not the stage's leaves it (fill_params).
        const float alpha = roughness_to_alpha(l.material->roughness_of_texel(looked_up_[0][j]));
        const uint32_t i = l.lanes[j];
        if ((alpha < kMinMicrofacetAlpha) != smooth_model) unfit_.push_back(i);
        alpha_[i] = GgxDistribution(alpha).alpha();
      }
      continue;
    }
    l.material->color_image()->eval_many(n, l.u.data(), l.v.data(), looked_up_[0].data(),
                                         looked_up_[1].data(), looked_up_[2].data());
    // A plastic's sampling weight follows its colour (PlasticBsdf::with_color, as bsdf_at).
    const auto* plastic = std::get_if<PlasticBsdf>(&l.material->bsdf().model());
    for (size_t j = 0; j < n; ++j) {
      // Material::color_at on the looked-up texel; fill_params's finiteness check.
      const Spectrum c = l.material->color_of_texel(
          Spectrum(looked_up_[0][j], looked_up_[1][j], looked_up_[2][j]));
      const uint32_t i = l.lanes[j];
      if (!is_finite(c)) unfit_.push_back(i);
      for (int k = 0; k < 3; ++k) colour_[k][i] = c[k];
      if (plastic) spec_weight_[i] = plastic->with_color(c).specular_sampling_weight();
    }
  }
}

void SurfaceStage::compute(const IntegratorSettings& settings, bool scene_next_event) {
  const bool next_event = estimates_light(scene_next_event);
  const size_t n = count_;
  if (n == 0) return;
  look_up_textures();
  // Lanes are staged unless their parameters leave the model; normal-mapped lanes are marked
  // (listed by add_many, which so writes nothing per plain lane).
  for (size_t i = 0; i < n; ++i) staged_[i] = 1;
  for (const uint32_t i : unfit_) staged_[i] = 0;
  const bool any_mapped = !mapped_lanes_.empty();
  if (any_mapped) {
    for (size_t i = 0; i < n; ++i) mapped_[i] = 0;
    for (const uint32_t i : mapped_lanes_) mapped_[i] = -1;
  }
  const LightSampler& sampler = scene_.mis_light_sampler();  // stages: path integrator
  if (next_event) {
    if (sampler.spatial()) {
      // Chosen by the light tree at each lane's point and normal, the lanes' walks together
      // (LightSampler::choose_many); a lane none of whose lights can reach its point has no
      // light (-1, no light sample).
      choose_p_.resize(n);
      choose_n_.resize(n);
      for (size_t i = 0; i < n; ++i) {
        choose_p_[i] = vec3(p_[0][i], p_[1][i], p_[2][i]);
        choose_n_[i] = vec3(ng_[0][i], ng_[1][i], ng_[2][i]);
      }
      sampler.choose_many(n, choose_p_.data(), choose_n_.data(), u_light_.data(), light_.data(),
                          l_pmf_.data());
    } else {
      choose_lights(sampler.cdf().data(), int32_t(sampler.cdf().size()), n, u_light_.data(),
                    light_.data());
    }
    // Each lane's light kind and its index among the lights of that kind; one pass of each kind's
    // kernel then serves all of its lanes.
    const bool spatial = sampler.spatial();
    lane_kind_.resize(n);
    lane_slot_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const int32_t light = light_[i];
      lane_kind_[i] = light < 0 ? -1 : lights_.kind[size_t(light)];
      lane_slot_[i] = light < 0 ? 0 : lights_.index[size_t(light)];
    }
    const float* const ref[3] = {p_[0].data(), p_[1].data(), p_[2].data()};
    const float* const s[2] = {u_point_[0].data(), u_point_[1].data()};
    LightSampleArrays out;
    out.ok = light_ok_.data();
    out.distance = l_distance_.data();
    out.pdf = l_pdf_.data();
    for (int c = 0; c < 3; ++c) {
      out.wi[c] = l_wi_[c].data();
      out.p[c] = l_p_[c].data();
      out.e[c] = l_error_[c].data();
      out.n[c] = l_n_[c].data();
      out.value[c] = l_value_[c].data();
    }
    // Each kind's kernel: a pass per light, or with many lights one pass over the lanes with
    // each lane's light's constants fetched into arrays (LightRows).
    const int32_t* kinds = lane_kind_.data();
    const int32_t* slots = lane_slot_.data();
    if (quad_rows_.rows() > 0) quad_light_samples(n, kinds, slots, quad_rows_, ref, s, out);
    if (sphere_rows_.rows() > 0) sphere_light_samples(n, kinds, slots, sphere_rows_, ref, s, out);
    if (point_rows_.rows() > 0) point_light_samples(n, kinds, slots, point_rows_, ref, out);
    // What the kernels leave: the choice's probability, the delta flags, a directional light's
    // whole sample (the same everywhere). Point and directional lights are deltas: no MIS
    // weight. (No constant environment: the path integrator, the stages' only user, leaves it
    // to BSDF sampling and never chooses it.)
    for (size_t i = 0; i < n; ++i) {
      const int32_t light = light_[i];
      l_delta_[i] = 0;
      if (light < 0) {
        light_ok_[i] = 0;
        continue;
      }
      const size_t index = size_t(lane_slot_[i]);
      if (!spatial) l_pmf_[i] = sampler.pmf(light);
      switch (lane_kind_[i]) {
        case StagedLights::kQuad:
          if (lights_.quads[index].texture) emission_lanes_.push_back(uint32_t(i));
          break;
        case StagedLights::kSphere:
          break;
        case StagedLights::kPoint:
          l_delta_[i] = 1;
          break;
        case StagedLights::kDirectional: {
          const StagedLights::DistantSource& d = lights_.distant[index];
          l_delta_[i] = 1;
          light_ok_[i] = 1;
          l_distance_[i] = kInfinity;
          l_pdf_[i] = 1.f;
          for (int c = 0; c < 3; ++c) {
            l_wi_[c][i] = d.wi[c];
            l_n_[c][i] = 0.f;
            l_p_[c][i] = 0.f;
            l_error_[c][i] = 0.f;
            l_value_[c][i] = d.irradiance[c];
          }
          break;
        }
        default:
          own_code_lanes_.push_back(uint32_t(i));
      }
    }
    if (!emission_lanes_.empty()) look_up_emission();
  }
  if (!own_code_lanes_.empty()) sample_own_code_lights();
  Lanes L;
  for (int c = 0; c < 3; ++c) {
    L.p[c] = p_[c].data();
    L.e[c] = p_error_[c].data();
    L.ng[c] = ng_[c].data();
    L.ns[c] = ns_[c].data();
    L.dir[c] = dir_[c].data();
    L.beta[c] = beta_[c].data();
    L.colour[c] = colour_[c].data();
    L.f_ms[c] = f_ms_[c].data();
    L.l_wi[c] = l_wi_[c].data();
    L.l_p[c] = l_p_[c].data();
    L.l_error[c] = l_error_[c].data();
    L.l_n[c] = l_n_[c].data();
    L.l_value[c] = l_value_[c].data();
    L.s_origin[c] = s_origin_[c].data();
    L.s_dir[c] = s_dir_[c].data();
    L.s_contrib[c] = s_contrib_[c].data();
    L.origin[c] = origin_[c].data();
    L.wo[c] = wo_[c].data();
    L.beta_out[c] = beta_out_[c].data();
  }
  L.alpha = alpha_.data();
  L.coat_eta = coat_eta_.data();
  L.spec_weight = spec_weight_.data();
  L.diffuse_scale = diffuse_scale_.data();
  L.metallic = metallic_.data();
  L.roughness = roughness_.data();
  L.e_avg = e_avg_.data();
  L.dielectric_avg = dielectric_avg_.data();
  L.table = table_.data();
  L.nodes = nodes_.data();
  L.tables = lane::Tables{table_cosines_.data(), table_values_.data(), albedo_table_};
  L.u_lobe = u_lobe_.data();
  L.time = time_.data();
  L.mapped = mapped_.data();
  for (int c = 0; c < 3; ++c) {
    L.frame_s[c] = frame_s_[c].data();
    L.frame_t[c] = frame_t_[c].data();
    L.mapped_n[c] = mapped_n_[c].data();
  }
  L.eta = eta_.data();
  L.u_dir[0] = u_dir_[0].data();
  L.u_dir[1] = u_dir_[1].data();
  L.u_rr = u_rr_.data();
  L.depth = depth_.data();
  L.light_ok = light_ok_.data();
  L.l_delta = l_delta_.data();
  L.l_distance = l_distance_.data();
  L.l_pdf = l_pdf_.data();
  L.l_pmf = l_pmf_.data();
  L.staged = staged_.data();
  L.prev_delta = prev_delta_.data();
  L.alive = alive_.data();
  L.has_shadow = has_shadow_.data();
  L.nee_ray = nee_ray_.data();
  L.dims = dims_.data();
  L.s_t_max = s_t_max_.data();
  L.prev_pdf = prev_pdf_.data();
  L.eta_out = eta_out_.data();
  // The kernels in StageModel's order.
  using Kernel = void (*)(const Lanes&, size_t, bool, bool, int32_t);
  static constexpr Kernel kKernels[] = {
      lambert_step_kernel,          rough_conductor_step_kernel,  smooth_plastic_step_kernel,
      rough_plastic_step_kernel,    rough_dielectric_step_kernel, smooth_conductor_step_kernel,
      smooth_dielectric_step_kernel, metallic_roughness_step_kernel};
  static_assert(std::size(kKernels) == std::size(kStageModels));
  kKernels[size_t(model_)](L, n, next_event, any_mapped, int32_t(settings.rr_depth));
}

void SurfaceStage::look_up_emission() {
  // AreaLight::sample's radiance(TextureQuery{p, uv, time}) with Quad::sample's uv, the lane's
  // (u_x, u_y): the light's constant times its texel, negative texels emitting nothing. Each
  // textured quad's lanes looked up together.
  for (const StagedLights::QuadLight& q : lights_.quads) {
    if (!q.texture) continue;
    emission_of_.clear();
    emission_u_.clear();
    emission_v_.clear();
    for (const uint32_t i : emission_lanes_) {
      if (light_[i] != q.light) continue;
      emission_of_.push_back(i);
      emission_u_.push_back(u_point_[0][i]);
      emission_v_.push_back(u_point_[1][i]);
    }
    const size_t n = emission_of_.size();
    if (n == 0) continue;
    for (auto& a : looked_up_)
      if (a.size() < n) a.resize(n);
    q.texture->eval_many(n, emission_u_.data(), emission_v_.data(), looked_up_[0].data(),
                         looked_up_[1].data(), looked_up_[2].data());
    const Spectrum factor(q.radiance[0], q.radiance[1], q.radiance[2]);
    for (size_t j = 0; j < n; ++j) {
      const Spectrum value =
          factor * glm::max(Spectrum(looked_up_[0][j], looked_up_[1][j], looked_up_[2][j]),
                            Spectrum(0.f));
      for (int c = 0; c < 3; ++c) l_value_[c][emission_of_[j]] = value[c];
    }
  }
}

void SurfaceStage::sample_own_code_lights() {
  // path_scatter's call with the same point, time and sampler values: the same sample to the
  // bit, which the kernel then takes as it takes a quad's (a zero normal marks a point in free
  // space, an infinite distance a direction).
  const auto store = [&](uint32_t i, bool ok, const LightSample& ls) {
    light_ok_[i] = ok;
    l_delta_[i] = ls.is_delta;
    l_distance_[i] = ls.distance;
    l_pdf_[i] = ls.pdf;
    for (int c = 0; c < 3; ++c) {
      l_wi_[c][i] = ls.wi[c];
      l_p_[c][i] = ls.p[c];
      l_error_[c][i] = ls.p_error[c];
      l_n_[c][i] = ls.n[c];
      l_value_[c][i] = ls.value[c];
    }
  };
  // The environment's lanes go together to its sample_many (an environment map's sampling is a
  // chain of table loads, which it then overlaps across lanes); other lights one lane at a time.
  const int environment = scene_.environment_light();
  environment_lanes_.clear();
  many_refs_.clear();
  many_times_.clear();
  many_u_.clear();
  for (const uint32_t i : own_code_lanes_) {
    const vec3 ref(p_[0][i], p_[1][i], p_[2][i]);
    const vec2 u(u_point_[0][i], u_point_[1][i]);
    if (light_[i] == environment) {
      environment_lanes_.push_back(i);
      many_refs_.push_back(ref);
      many_times_.push_back(time_[i]);
      many_u_.push_back(u);
      continue;
    }
    LightSample ls;
    const bool ok = scene_.mis_light(light_[i]).sample(ref, time_[i], u, &ls);  // path integrator
    store(i, ok, ls);
  }
  const size_t n = environment_lanes_.size();
  if (n == 0) return;
  if (many_out_.size() < n) {  // (many_ok_ holds as many as many_out_)
    many_out_.resize(n);
    many_ok_ = std::make_unique<bool[]>(n);
  }
  scene_.mis_light(environment).sample_many(n, many_refs_.data(), many_times_.data(), many_u_.data(),
                                            many_out_.data(), many_ok_.get());
  for (size_t k = 0; k < n; ++k) store(environment_lanes_[k], many_ok_[k], many_out_[k]);
}

uint64_t SurfaceStage::deliver(const uint32_t* live, PathState* states, Sampler::Cursor* cursors,
                              uint8_t* goes_on, uint8_t* has_shadow, ShadowQuery* shadows,
                              std::vector<uint32_t>* unstaged) const {
  // One loop over the lanes with the tests as values where it can (the per-lane calls and
  // branches on the random alive and shadow masks cost a fifth of the driver's own time).
  uint64_t rays = 0;
  for (size_t i = 0; i < count_; ++i) {
    if (!staged_[i]) {
      unstaged->push_back(uint32_t(i));
      continue;
    }
    const uint32_t k = slot_[i];
    rays += uint64_t(nee_ray_[i] != 0);
    // Field by field into the slot: a ShadowQuery built elsewhere and copied whole stalled on
    // store forwarding (4-byte stores read back as 16-byte loads).
    ShadowQuery& q = shadows[k];
    for (int c = 0; c < 3; ++c) {
      q.ray.origin[c] = s_origin_[c][i];
      q.ray.direction[c] = s_dir_[c][i];
      q.contribution[c] = s_contrib_[c][i];
    }
    q.ray.time = time_[i];
    q.ray.t_max = s_t_max_[i];
    has_shadow[k] = has_shadow_[i] != 0;
    goes_on[k] = alive_[i] != 0;
    if (!alive_[i]) continue;
    const uint32_t p = live[k];
    PathState& s = states[p];
    s.beta = Spectrum(beta_out_[0][i], beta_out_[1][i], beta_out_[2][i]);
    s.prev_pdf = prev_pdf_[i];
    s.prev_delta = prev_delta_[i] != 0;
    s.prev_p = vec3(p_[0][i], p_[1][i], p_[2][i]);
    s.prev_n = vec3(ng_[0][i], ng_[1][i], ng_[2][i]);
    s.ray = Ray{vec3(origin_[0][i], origin_[1][i], origin_[2][i]),
                vec3(wo_[0][i], wo_[1][i], wo_[2][i]), time_[i]};
    s.eta = eta_out_[i];
    ++s.depth;
    cursors[p].dimension += uint64_t(dims_[i]);
  }
  return rays;
}

}  // namespace penumbra
