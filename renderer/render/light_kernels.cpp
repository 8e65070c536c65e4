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

namespace penumbra {

// Quad::sample followed by AreaLight::sample for the entries whose light is `id`, over arrays;
// other entries keep what they hold. Operation for operation as the scalar code: glm's dot sums
// x, y, z in that order, length is sqrt(dot), a vector divided by a scalar divides each
// component, and every comparison that rejects a sample is the scalar one (NaNs included).
PENUMBRA_SIMD_CLONES
void quad_light_samples(const float* __restrict q_origin, const float* __restrict q_u,
                        const float* __restrict q_v, const float* __restrict q_n, float q_area,
                        int32_t id, size_t n, const int32_t* __restrict light,
                        const float* __restrict ref_x, const float* __restrict ref_y,
                        const float* __restrict ref_z, const float* __restrict u_x,
                        const float* __restrict u_y, int32_t* __restrict ok,
                        float* __restrict wi_x, float* __restrict wi_y, float* __restrict wi_z,
                        float* __restrict distance, float* __restrict pdf, float* __restrict p_x,
                        float* __restrict p_y, float* __restrict p_z, float* __restrict e_x,
                        float* __restrict e_y, float* __restrict e_z) {
  constexpr float g6 = gamma_bound(6);
  const float ox = q_origin[0], oy = q_origin[1], oz = q_origin[2];
  const float ux = q_u[0], uy = q_u[1], uz = q_u[2], vx = q_v[0], vy = q_v[1], vz = q_v[2];
  const float nx = q_n[0], ny = q_n[1], nz = q_n[2];
  for (size_t i = 0; i < n; ++i) {
    // Quad::sample: p = o + s u + t v and its error bound (pbrt-v4 section 6.8.1).
    const float sux = u_x[i] * ux, suy = u_x[i] * uy, suz = u_x[i] * uz;
    const float svx = u_y[i] * vx, svy = u_y[i] * vy, svz = u_y[i] * vz;
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
    const float density = (cos_l > 0.f) & (q_area > 0.f) ? ratio : 0.f;
    // AreaLight::sample: a finite positive density, a positive distance, the front side (&
    // rather than &&: no branches in the loop).
    const float dist = std::sqrt(dist2);
    const float dx = wx / dist, dy = wy / dist, dz = wz / dist;
    const bool good = (density > 0.f) & (density < kInfinity) & (dist > 0.f) &
                      !(((nx * dx + ny * dy) + nz * dz) >= 0.f);
    const Mask mine = mask(light[i] == id);
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
  }
}

// PointLight::sample for the entries whose light is `id`, over arrays (glm's dot and the
// component-wise divisions as the scalar code does them).
PENUMBRA_SIMD_CLONES
void point_light_samples(const float* __restrict position, const float* __restrict intensity,
                         int32_t id, size_t n, const int32_t* __restrict light,
                         const float* __restrict ref_x, const float* __restrict ref_y,
                         const float* __restrict ref_z, int32_t* __restrict ok,
                         float* __restrict wi_x, float* __restrict wi_y, float* __restrict wi_z,
                         float* __restrict distance, float* __restrict pdf,
                         float* __restrict p_x, float* __restrict p_y, float* __restrict p_z,
                         float* __restrict value_x, float* __restrict value_y,
                         float* __restrict value_z) {
  const float sx = position[0], sy = position[1], sz = position[2];
  const float ix = intensity[0], iy = intensity[1], iz = intensity[2];
  for (size_t i = 0; i < n; ++i) {
    const float dx = sx - ref_x[i], dy = sy - ref_y[i], dz = sz - ref_z[i];
    const float dist2 = (dx * dx + dy * dy) + dz * dz;
    const float dist = std::sqrt(dist2);
    const Mask mine = mask(light[i] == id);
    ok[i] = when(mine, int32_t(dist2 > 0.f), ok[i]);
    wi_x[i] = when(mine, dx / dist, wi_x[i]);
    wi_y[i] = when(mine, dy / dist, wi_y[i]);
    wi_z[i] = when(mine, dz / dist, wi_z[i]);
    distance[i] = when(mine, dist, distance[i]);
    pdf[i] = when(mine, 1.f, pdf[i]);
    p_x[i] = when(mine, sx, p_x[i]);
    p_y[i] = when(mine, sy, p_y[i]);
    p_z[i] = when(mine, sz, p_z[i]);
    value_x[i] = when(mine, ix / dist2, value_x[i]);
    value_y[i] = when(mine, iy / dist2, value_y[i]);
    value_z[i] = when(mine, iz / dist2, value_z[i]);
  }
}

// LightSampler::choose for every entry: the first light whose cumulative probability exceeds
// u is the number of lights whose cumulative probability does not (the table is sorted), and
// the last light if rounding left u past them all.
PENUMBRA_SIMD_CLONES
void choose_lights(const float* __restrict cdf, int32_t lights, size_t n,
                   const float* __restrict u, int32_t* __restrict light) {
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
  // Each staged quad or point light is a pass over all of a stage's lanes: past a few of them
  // (a scene of many lights, chosen by the light tree) the lanes sample their lights one by one.
  if (quads.size() + points.size() > kMaxStaged) {
    for (size_t l = 0; l < lights; ++l)
      if (kind[l] == kQuad || kind[l] == kPoint) kind[l] = kOwnCode, index[l] = -1;
    quads.clear();
    points.clear();
  }
}

}  // namespace penumbra
