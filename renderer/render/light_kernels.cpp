#include "renderer/render/light_kernels.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/simd_clones.h"
#include "renderer/lights/area_light.h"
#include "renderer/lights/directional_light.h"
#include "renderer/lights/light_sampler.h"
#include "renderer/lights/point_light.h"
#include "renderer/sampling/sampling.h"
#include "renderer/shapes/quad.h"
#include "renderer/shapes/sphere.h"
#include "renderer/shapes/sphere_sample.h"

namespace penumbra {
namespace {

// A kernel's array parameters (GCC trusts __restrict on parameters only: without it the
// kernels' many outputs would each need a run-time overlap check, and the loops stay scalar).
using In = const float* __restrict;
using Out = float* __restrict;

// LightRows::fetch for rows of kWidth floats.
template <int32_t kWidth>
void gather_rows(const float* table, int32_t of_kind, size_t n, const int32_t* kind,
                 const int32_t* slot, std::vector<std::vector<float>>& fields) {
  float* out[kWidth];
  for (int32_t f = 0; f < kWidth; ++f) out[f] = fields[size_t(f)].data();
  for (size_t i = 0; i < n; ++i) {
    if (kind[i] != of_kind) continue;
    const float* row = table + size_t(slot[i]) * size_t(kWidth);
    for (int32_t f = 0; f < kWidth; ++f) out[f][i] = row[f];
  }
}

}  // namespace

void LightRows::fetch(size_t n, const int32_t* kind, const int32_t* slot) {
  const size_t rows = table_.size() / size_t(width_);
  if (rows == 0) return;
  if (fields_[0].size() < n)
    for (std::vector<float>& f : fields_) f.resize(n);
  switch (width_) {
    case StagedLights::kQuadRow:
      return gather_rows<StagedLights::kQuadRow>(table_.data(), kind_, n, kind, slot, fields_);
    case StagedLights::kSphereRow:
      return gather_rows<StagedLights::kSphereRow>(table_.data(), kind_, n, kind, slot, fields_);
    case StagedLights::kPointRow:
      return gather_rows<StagedLights::kPointRow>(table_.data(), kind_, n, kind, slot, fields_);
  }
}

namespace {

// Quad::sample followed by AreaLight::sample for lane i, whose light is this quad if `mine`;
// other lanes keep what they hold. Operation for operation as the scalar code: glm's dot sums x,
// y, z in that order, length is sqrt(dot), a vector divided by a scalar divides each component,
// and every comparison that rejects a sample is the scalar one (NaNs included).
[[gnu::always_inline]] inline void quad_lane(
    size_t i, Mask mine, float ox, float oy, float oz, float ux, float uy, float uz, float vx,
    float vy, float vz, float nx, float ny, float nz, float q_area, float rad_x, float rad_y,
    float rad_z, In ref_x, In ref_y, In ref_z, In s_x, In s_y, int32_t* __restrict ok, Out wi_x,
    Out wi_y, Out wi_z, Out distance, Out pdf, Out p_x, Out p_y, Out p_z, Out e_x, Out e_y, Out e_z,
    Out n_x, Out n_y, Out n_z, Out value_x, Out value_y, Out value_z) {
  constexpr float g6 = gamma_bound(6);
  // Quad::sample: p = o + s u + t v and its error bound (pbrt-v4 section 6.8.1).
  const float sux = s_x[i] * ux, suy = s_x[i] * uy, suz = s_x[i] * uz;
  const float svx = s_y[i] * vx, svy = s_y[i] * vy, svz = s_y[i] * vz;
  const float px = (ox + sux) + svx, py = (oy + suy) + svy, pz = (oz + suz) + svz;
  const float ex = g6 * ((std::fabs(ox) + std::fabs(sux)) + std::fabs(svx));
  const float ey = g6 * ((std::fabs(oy) + std::fabs(suy)) + std::fabs(svy));
  const float ez = g6 * ((std::fabs(oz) + std::fabs(suz)) + std::fabs(svz));
  // area_to_solid_angle (shapes/shape.h). Divided in every lane and then selected: a division
  // under a condition is not if-converted; the selected value is the scalar one.
  const float wx = px - ref_x[i], wy = py - ref_y[i], wz = pz - ref_z[i];
  const float dist2 = (wx * wx + wy * wy) + wz * wz;
  const float cos_l = std::fabs((nx * wx + ny * wy) + nz * wz) / std::sqrt(dist2);
  const float ratio = dist2 / (cos_l * q_area);
  const float density = ((cos_l > 0.f) & (q_area > 0.f)) ? ratio : 0.f;
  // AreaLight::sample: a finite positive density, a positive distance, the front side (&
  // rather than &&: no branches in the loop).
  const float dist = std::sqrt(dist2);
  const float dx = wx / dist, dy = wy / dist, dz = wz / dist;
  const bool good = (density > 0.f) & (density < kInfinity) & (dist > 0.f) &
                    !(((nx * dx + ny * dy) + nz * dz) >= 0.f);
  ok[i] = when(mine, int32_t(good), ok[i]);
  wi_x[i] = when(mine, dx, wi_x[i]);
  wi_y[i] = when(mine, dy, wi_y[i]);
  wi_z[i] = when(mine, dz, wi_z[i]);
  distance[i] = when(mine, dist, distance[i]);
  pdf[i] = when(mine, density, pdf[i]);
  p_x[i] = when(mine, px, p_x[i]);
  p_y[i] = when(mine, py, p_y[i]);
  p_z[i] = when(mine, pz, p_z[i]);
  e_x[i] = when(mine, ex, e_x[i]);
  e_y[i] = when(mine, ey, e_y[i]);
  e_z[i] = when(mine, ez, e_z[i]);
  n_x[i] = when(mine, nx, n_x[i]);
  n_y[i] = when(mine, ny, n_y[i]);
  n_z[i] = when(mine, nz, n_z[i]);
  value_x[i] = when(mine, rad_x, value_x[i]);
  value_y[i] = when(mine, rad_y, value_y[i]);
  value_z[i] = when(mine, rad_z, value_z[i]);
}

// The quad lanes with their quads' constants in arrays (LightRows).
PENUMBRA_SIMD_CLONES
void quad_kernel(size_t n, const int32_t* __restrict kind, In o_x, In o_y, In o_z, In u_x, In u_y,
                 In u_z, In v_x, In v_y, In v_z, In nrm_x, In nrm_y, In nrm_z, In area, In rad_x,
                 In rad_y, In rad_z, In ref_x, In ref_y, In ref_z, In s_x, In s_y,
                 int32_t* __restrict ok, Out wi_x, Out wi_y, Out wi_z, Out distance, Out pdf,
                 Out p_x, Out p_y, Out p_z, Out e_x, Out e_y, Out e_z, Out n_x, Out n_y, Out n_z,
                 Out value_x, Out value_y, Out value_z) {
  for (size_t i = 0; i < n; ++i)
    quad_lane(i, mask(kind[i] == StagedLights::kQuad), o_x[i], o_y[i], o_z[i], u_x[i], u_y[i],
              u_z[i], v_x[i], v_y[i], v_z[i], nrm_x[i], nrm_y[i], nrm_z[i], area[i], rad_x[i],
              rad_y[i], rad_z[i], ref_x, ref_y, ref_z, s_x, s_y, ok, wi_x, wi_y, wi_z, distance,
              pdf, p_x, p_y, p_z, e_x, e_y, e_z, n_x, n_y, n_z, value_x, value_y, value_z);
}

// The lanes of one quad (its slot `row`), its constants as values.
PENUMBRA_SIMD_CLONES
void quad_kernel_one(size_t n, const int32_t* __restrict kind, const int32_t* __restrict slot,
                     int32_t row, const float* c, In ref_x, In ref_y, In ref_z, In s_x, In s_y,
                     int32_t* __restrict ok, Out wi_x, Out wi_y, Out wi_z, Out distance, Out pdf,
                     Out p_x, Out p_y, Out p_z, Out e_x, Out e_y, Out e_z, Out n_x, Out n_y,
                     Out n_z, Out value_x, Out value_y, Out value_z) {
  const float ox = c[0], oy = c[1], oz = c[2], ux = c[3], uy = c[4], uz = c[5], vx = c[6];
  const float vy = c[7], vz = c[8], nx = c[9], ny = c[10], nz = c[11], area = c[12];
  const float rx = c[13], ry = c[14], rz = c[15];
  for (size_t i = 0; i < n; ++i)
    quad_lane(i, mask(kind[i] == StagedLights::kQuad) & mask(slot[i] == row), ox, oy, oz, ux, uy,
              uz, vx, vy, vz, nx, ny, nz, area, rx, ry, rz, ref_x, ref_y, ref_z, s_x, s_y, ok, wi_x,
              wi_y, wi_z, distance, pdf, p_x, p_y, p_z, e_x, e_y, e_z, n_x, n_y, n_z, value_x,
              value_y, value_z);
}

// sample_sphere (through the arithmetic it shares, shapes/sphere_sample.h) followed by
// AreaLight::sample for lane i, whose light is this sphere if `mine`; other lanes keep what they
// hold.
[[gnu::always_inline]] inline void sphere_lane(size_t i, Mask mine, float cx, float cy, float cz,
                                               float radius, float rad_x, float rad_y, float rad_z,
                                               In ref_x, In ref_y, In ref_z, In s_x, In s_y,
                                               int32_t* __restrict ok, Out wi_x, Out wi_y, Out wi_z,
                                               Out distance, Out pdf, Out p_x, Out p_y, Out p_z,
                                               Out e_x, Out e_y, Out e_z, Out n_x, Out n_y, Out n_z,
                                               Out value_x, Out value_y, Out value_z) {
  float sp[3], sn[3], se[3], spdf;
  sphere_solid_angle_sample(cx, cy, cz, radius, ref_x[i], ref_y[i], ref_z[i], s_x[i], s_y[i], sp,
                            sn, se, &spdf);
  // AreaLight::sample: a finite positive density, a positive distance, the front side.
  const float wx = sp[0] - ref_x[i], wy = sp[1] - ref_y[i], wz = sp[2] - ref_z[i];
  const float dist = std::sqrt((wx * wx + wy * wy) + wz * wz);
  const float dx = wx / dist, dy = wy / dist, dz = wz / dist;
  const bool good = (spdf > 0.f) & (spdf < kInfinity) & (dist > 0.f) &
                    !(((sn[0] * dx + sn[1] * dy) + sn[2] * dz) >= 0.f);
  ok[i] = when(mine, int32_t(good), ok[i]);
  wi_x[i] = when(mine, dx, wi_x[i]);
  wi_y[i] = when(mine, dy, wi_y[i]);
  wi_z[i] = when(mine, dz, wi_z[i]);
  distance[i] = when(mine, dist, distance[i]);
  pdf[i] = when(mine, spdf, pdf[i]);
  p_x[i] = when(mine, sp[0], p_x[i]);
  p_y[i] = when(mine, sp[1], p_y[i]);
  p_z[i] = when(mine, sp[2], p_z[i]);
  e_x[i] = when(mine, se[0], e_x[i]);
  e_y[i] = when(mine, se[1], e_y[i]);
  e_z[i] = when(mine, se[2], e_z[i]);
  n_x[i] = when(mine, sn[0], n_x[i]);
  n_y[i] = when(mine, sn[1], n_y[i]);
  n_z[i] = when(mine, sn[2], n_z[i]);
  value_x[i] = when(mine, rad_x, value_x[i]);
  value_y[i] = when(mine, rad_y, value_y[i]);
  value_z[i] = when(mine, rad_z, value_z[i]);
}

// The sphere lanes with their spheres' constants in arrays (LightRows).
PENUMBRA_SIMD_CLONES
void sphere_kernel(size_t n, const int32_t* __restrict kind, In c_x, In c_y, In c_z, In radius,
                   In rad_x, In rad_y, In rad_z, In ref_x, In ref_y, In ref_z, In s_x, In s_y,
                   int32_t* __restrict ok, Out wi_x, Out wi_y, Out wi_z, Out distance, Out pdf,
                   Out p_x, Out p_y, Out p_z, Out e_x, Out e_y, Out e_z, Out n_x, Out n_y, Out n_z,
                   Out value_x, Out value_y, Out value_z) {
  for (size_t i = 0; i < n; ++i)
    sphere_lane(i, mask(kind[i] == StagedLights::kSphere), c_x[i], c_y[i], c_z[i], radius[i],
                rad_x[i], rad_y[i], rad_z[i], ref_x, ref_y, ref_z, s_x, s_y, ok, wi_x, wi_y, wi_z,
                distance, pdf, p_x, p_y, p_z, e_x, e_y, e_z, n_x, n_y, n_z, value_x, value_y,
                value_z);
}

// The lanes of one sphere (its slot `row`), its constants as values.
PENUMBRA_SIMD_CLONES
void sphere_kernel_one(size_t n, const int32_t* __restrict kind, const int32_t* __restrict slot,
                       int32_t row, const float* c, In ref_x, In ref_y, In ref_z, In s_x, In s_y,
                       int32_t* __restrict ok, Out wi_x, Out wi_y, Out wi_z, Out distance, Out pdf,
                       Out p_x, Out p_y, Out p_z, Out e_x, Out e_y, Out e_z, Out n_x, Out n_y,
                       Out n_z, Out value_x, Out value_y, Out value_z) {
  const float cx = c[0], cy = c[1], cz = c[2], radius = c[3], rx = c[4], ry = c[5], rz = c[6];
  for (size_t i = 0; i < n; ++i)
    sphere_lane(i, mask(kind[i] == StagedLights::kSphere) & mask(slot[i] == row), cx, cy, cz,
                radius, rx, ry, rz, ref_x, ref_y, ref_z, s_x, s_y, ok, wi_x, wi_y, wi_z, distance,
                pdf, p_x, p_y, p_z, e_x, e_y, e_z, n_x, n_y, n_z, value_x, value_y, value_z);
}

// PointLight::sample for lane i, whose light is this one if `mine`; other lanes keep what they
// hold (glm's dot and the component-wise divisions as the scalar code does them).
[[gnu::always_inline]] inline void point_lane(size_t i, Mask mine, float sx, float sy, float sz,
                                              float int_x, float int_y, float int_z, In ref_x,
                                              In ref_y, In ref_z, int32_t* __restrict ok, Out wi_x,
                                              Out wi_y, Out wi_z, Out distance, Out pdf, Out p_x,
                                              Out p_y, Out p_z, Out e_x, Out e_y, Out e_z, Out n_x,
                                              Out n_y, Out n_z, Out value_x, Out value_y,
                                              Out value_z) {
  const float dx = sx - ref_x[i], dy = sy - ref_y[i], dz = sz - ref_z[i];
  const float dist2 = (dx * dx + dy * dy) + dz * dz;
  const float dist = std::sqrt(dist2);
  ok[i] = when(mine, int32_t(dist2 > 0.f), ok[i]);
  wi_x[i] = when(mine, dx / dist, wi_x[i]);
  wi_y[i] = when(mine, dy / dist, wi_y[i]);
  wi_z[i] = when(mine, dz / dist, wi_z[i]);
  distance[i] = when(mine, dist, distance[i]);
  pdf[i] = when(mine, 1.f, pdf[i]);
  p_x[i] = when(mine, sx, p_x[i]);
  p_y[i] = when(mine, sy, p_y[i]);
  p_z[i] = when(mine, sz, p_z[i]);
  e_x[i] = when(mine, 0.f, e_x[i]);
  e_y[i] = when(mine, 0.f, e_y[i]);
  e_z[i] = when(mine, 0.f, e_z[i]);
  n_x[i] = when(mine, 0.f, n_x[i]);
  n_y[i] = when(mine, 0.f, n_y[i]);
  n_z[i] = when(mine, 0.f, n_z[i]);
  value_x[i] = when(mine, int_x / dist2, value_x[i]);
  value_y[i] = when(mine, int_y / dist2, value_y[i]);
  value_z[i] = when(mine, int_z / dist2, value_z[i]);
}

// The point-light lanes with their lights' constants in arrays (LightRows).
PENUMBRA_SIMD_CLONES
void point_kernel(size_t n, const int32_t* __restrict kind, In pos_x, In pos_y, In pos_z, In int_x,
                  In int_y, In int_z, In ref_x, In ref_y, In ref_z, int32_t* __restrict ok,
                  Out wi_x, Out wi_y, Out wi_z, Out distance, Out pdf, Out p_x, Out p_y, Out p_z,
                  Out e_x, Out e_y, Out e_z, Out n_x, Out n_y, Out n_z, Out value_x, Out value_y,
                  Out value_z) {
  for (size_t i = 0; i < n; ++i)
    point_lane(i, mask(kind[i] == StagedLights::kPoint), pos_x[i], pos_y[i], pos_z[i], int_x[i],
               int_y[i], int_z[i], ref_x, ref_y, ref_z, ok, wi_x, wi_y, wi_z, distance, pdf, p_x,
               p_y, p_z, e_x, e_y, e_z, n_x, n_y, n_z, value_x, value_y, value_z);
}

// The lanes of one point light (its slot `row`), its constants as values.
PENUMBRA_SIMD_CLONES
void point_kernel_one(size_t n, const int32_t* __restrict kind, const int32_t* __restrict slot,
                      int32_t row, const float* c, In ref_x, In ref_y, In ref_z,
                      int32_t* __restrict ok, Out wi_x, Out wi_y, Out wi_z, Out distance, Out pdf,
                      Out p_x, Out p_y, Out p_z, Out e_x, Out e_y, Out e_z, Out n_x, Out n_y,
                      Out n_z, Out value_x, Out value_y, Out value_z) {
  const float sx = c[0], sy = c[1], sz = c[2], ix = c[3], iy = c[4], iz = c[5];
  for (size_t i = 0; i < n; ++i)
    point_lane(i, mask(kind[i] == StagedLights::kPoint) & mask(slot[i] == row), sx, sy, sz, ix, iy,
               iz, ref_x, ref_y, ref_z, ok, wi_x, wi_y, wi_z, distance, pdf, p_x, p_y, p_z, e_x,
               e_y, e_z, n_x, n_y, n_z, value_x, value_y, value_z);
}

}  // namespace

namespace {

// kernel(in..., the sample's output arrays).
template <class Kernel, class... In>
void with_outputs(Kernel kernel, const LightSampleArrays& o, In... in) {
  kernel(in..., o.ok, o.wi[0], o.wi[1], o.wi[2], o.distance, o.pdf, o.p[0], o.p[1], o.p[2], o.e[0],
         o.e[1], o.e[2], o.n[0], o.n[1], o.n[2], o.value[0], o.value[1], o.value[2]);
}

}  // namespace

void quad_light_samples(size_t n, const int32_t* kind, const int32_t* slot, LightRows& q,
                        const float* const* ref, const float* const* s,
                        const LightSampleArrays& out) {
  if (q.rows() <= LightRows::kFewRows) {
    for (size_t r = 0; r < q.rows(); ++r)
      with_outputs(quad_kernel_one, out, n, kind, slot, int32_t(r), q.row(r), ref[0], ref[1],
                   ref[2], s[0], s[1]);
    return;
  }
  q.fetch(n, kind, slot);
  with_outputs(quad_kernel, out, n, kind, q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8],
               q[9], q[10], q[11], q[12], q[13], q[14], q[15], ref[0], ref[1], ref[2], s[0], s[1]);
}

void sphere_light_samples(size_t n, const int32_t* kind, const int32_t* slot, LightRows& b,
                          const float* const* ref, const float* const* s,
                          const LightSampleArrays& out) {
  if (b.rows() <= LightRows::kFewRows) {
    for (size_t r = 0; r < b.rows(); ++r)
      with_outputs(sphere_kernel_one, out, n, kind, slot, int32_t(r), b.row(r), ref[0], ref[1],
                   ref[2], s[0], s[1]);
    return;
  }
  b.fetch(n, kind, slot);
  with_outputs(sphere_kernel, out, n, kind, b[0], b[1], b[2], b[3], b[4], b[5], b[6], ref[0],
               ref[1], ref[2], s[0], s[1]);
}

void point_light_samples(size_t n, const int32_t* kind, const int32_t* slot, LightRows& l,
                         const float* const* ref, const LightSampleArrays& out) {
  if (l.rows() <= LightRows::kFewRows) {
    for (size_t r = 0; r < l.rows(); ++r)
      with_outputs(point_kernel_one, out, n, kind, slot, int32_t(r), l.row(r), ref[0], ref[1],
                   ref[2]);
    return;
  }
  l.fetch(n, kind, slot);
  with_outputs(point_kernel, out, n, kind, l[0], l[1], l[2], l[3], l[4], l[5], ref[0], ref[1],
               ref[2]);
}

// LightSampler::choose for every entry: the first light whose cumulative probability exceeds
// u is the number of lights whose cumulative probability does not (the table is sorted), and
// the last light if rounding left u past them all.
PENUMBRA_SIMD_CLONES
void choose_lights(In cdf, int32_t lights, size_t n, In u, int32_t* __restrict light) {
  for (size_t i = 0; i < n; ++i) light[i] = 0;
  for (int32_t l = 0; l < lights; ++l) {
    const float c = cdf[l];
    for (size_t i = 0; i < n; ++i) light[i] += int32_t(c <= u[i]);
  }
  for (size_t i = 0; i < n; ++i) light[i] = std::min(light[i], lights - 1);
}

StagedLights::StagedLights(const Scene& scene) {
  const size_t lights = size_t(scene.light_count());
  kind.assign(lights, kOwnCode);
  index.assign(lights, -1);
  for (size_t l = 0; l < lights; ++l) {
    const Light& light = scene.mis_light(int(l));  // the stages run the path integrator
    if (const auto* point = dynamic_cast<const PointLight*>(&light)) {
      PointSource p;
      p.light = int32_t(l);
      for (int c = 0; c < 3; ++c) {
        p.position[c] = point->position()[c];
        p.intensity[c] = point->intensity()[c];
      }
      kind[l] = kPoint;
      index[l] = int32_t(points.size());
      points.push_back(p);
      continue;
    }
    if (const auto* sun = dynamic_cast<const DirectionalLight*>(&light)) {
      DistantSource d;
      const vec3 wi = -sun->direction();  // DirectionalLight::sample's wi
      for (int c = 0; c < 3; ++c) {
        d.wi[c] = wi[c];
        d.irradiance[c] = sun->irradiance()[c];
      }
      kind[l] = kDirectional;
      index[l] = int32_t(distant.size());
      distant.push_back(d);
      continue;
    }
    const auto* area = dynamic_cast<const AreaLight*>(&light);
    if (!area) continue;
    if (const auto* sphere = dynamic_cast<const Sphere*>(&area->shape())) {
      if (area->textured() || !sphere->motion().is_static()) continue;
      SphereLight b;
      b.light = int32_t(l);
      const vec3 c = sphere->center_at(0.f);  // (the centre plus zero, as Sphere::sample takes it)
      const Spectrum r = area->radiance_factor();
      for (int k = 0; k < 3; ++k) {
        b.center[k] = c[k];
        b.radiance[k] = r[k];
      }
      b.radius = sphere->radius();
      kind[l] = kSphere;
      index[l] = int32_t(spheres.size());
      spheres.push_back(b);
      continue;
    }
    const auto* quad = dynamic_cast<const Quad*>(&area->shape());
    if (!quad || quad->moving()) continue;
    StagedLights::QuadLight q;
    if (area->textured()) {
      q.texture = dynamic_cast<const ImageSpectrumTexture*>(area->texture());
      if (!q.texture) continue;
    }
    q.light = int32_t(l);
    const QuadDesc& d = quad->desc();
    const vec3 n = quad->normal();
    const Spectrum r = area->radiance_factor();
    for (int c = 0; c < 3; ++c) {
      q.origin[c] = d.origin[c];
      q.u[c] = d.u[c];
      q.v[c] = d.v[c];
      q.n[c] = n[c];
      q.radiance[c] = r[c];
    }
    q.area = quad->area();
    kind[l] = kQuad;
    index[l] = int32_t(quads.size());
    quads.push_back(q);
  }
  for (const QuadLight& q : quads) {
    const float row[kQuadRow] = {q.origin[0], q.origin[1],   q.origin[2],   q.u[0],
                                 q.u[1],      q.u[2],        q.v[0],        q.v[1],
                                 q.v[2],      q.n[0],        q.n[1],        q.n[2],
                                 q.area,      q.radiance[0], q.radiance[1], q.radiance[2]};
    quad_table.insert(quad_table.end(), row, row + kQuadRow);
  }
  for (const SphereLight& b : spheres) {
    const float row[kSphereRow] = {b.center[0],   b.center[1],   b.center[2],  b.radius,
                                   b.radiance[0], b.radiance[1], b.radiance[2]};
    sphere_table.insert(sphere_table.end(), row, row + kSphereRow);
  }
  for (const PointSource& p : points) {
    const float row[kPointRow] = {p.position[0],  p.position[1],  p.position[2],
                                  p.intensity[0], p.intensity[1], p.intensity[2]};
    point_table.insert(point_table.end(), row, row + kPointRow);
  }
}

}  // namespace penumbra
