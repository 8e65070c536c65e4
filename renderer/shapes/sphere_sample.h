#pragma once
// A point on a sphere sampled by the solid angle it subtends from a reference point, as plain
// float arithmetic: sample_sphere (Sphere::sample) and the stages' sphere-light kernel
// (render/light_kernels.cpp) both inline this one function, so a path's light sample is the same
// bits in the scalar step and in SIMD lanes (both files are compiled without contraction into
// fused multiply-adds). Every branch is a select of values all lanes compute, so a loop over
// many points vectorises.
//
// Outside the sphere: a direction uniform in the cone of the sphere's silhouette, and the point
// where it meets the sphere found by the law of cosines in the triangle (ref, centre, point)
// rather than by a ray intersection (pbrt-v3 section 14.2.2); pdf 1 / (2 pi (1 - cos_max)) per
// solid angle. For tiny or distant spheres 1 - cos_max cancels catastrophically, and its series
// in sin^2 is exact enough. Inside (or on) the sphere: a point uniform over its area, and the
// solid-angle density of that point from ref.
#include <algorithm>
#include <cmath>

#include "renderer/core/ray.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

[[gnu::always_inline]] inline void sphere_solid_angle_sample(float cx, float cy, float cz,
                                                             float radius, float rx, float ry,
                                                             float rz, float u0, float u1, float* p,
                                                             float* n, float* p_error, float* pdf) {
  constexpr float g6 = gamma_bound(6);
  const float tx = cx - rx, ty = cy - ry, tz = cz - rz;
  const float dc2 = (tx * tx + ty * ty) + tz * tz;
  const float r2 = radius * radius;
  const bool inside = dc2 <= r2 * 1.0001f;
  float sin_phi, cos_phi;
  sincos_two_pi(u1, &sin_phi, &cos_phi);

  // Inside: square_to_uniform_sphere, then area_to_solid_angle over the area 4 pi r^2.
  const float z = 1.f - 2.f * u0;
  const float rr = safe_sqrt(1.f - z * z);
  const float ix = rr * cos_phi, iy = rr * sin_phi, iz = z;
  const float ipx = cx + radius * ix, ipy = cy + radius * iy, ipz = cz + radius * iz;
  const float iwx = ipx - rx, iwy = ipy - ry, iwz = ipz - rz;
  const float idist2 = (iwx * iwx + iwy * iwy) + iwz * iwz;
  const float icos = std::fabs((ix * iwx + iy * iwy) + iz * iwz) / std::sqrt(idist2);
  const float iarea = 4.f * kPi * r2;
  const float iratio = idist2 / (icos * iarea);
  const float ipdf = ((icos > 0.f) & (iarea > 0.f)) ? iratio : 0.f;

  // Outside: the cone towards the centre, in the frame of wc (Duff et al. 2017's basis, as Frame).
  const float dc = std::sqrt(dc2);
  const float wx = tx / dc, wy = ty / dc, wz = tz / dc;
  const float sign = std::copysign(1.f, wz);
  const float a = -1.f / (sign + wz);
  const float b = wx * wy * a;
  const float sx = 1.f + sign * wx * wx * a, sy = sign * b, sz = -sign * wx;
  const float vx = b, vy = sign + wy * wy * a, vz = -wy;
  const float sin2_max = r2 / dc2;
  const float cos_max = safe_sqrt(1.f - sin2_max);
  const bool series = sin2_max < 1e-3f;
  const float one_minus_cos_max =
      series ? sin2_max * 0.5f + sin2_max * sin2_max / 8.f : 1.f - cos_max;
  const float cos_t = 1.f - u0 * one_minus_cos_max;
  const float sin2_t = std::max(0.f, 1.f - cos_t * cos_t);
  const float sin2_t_exact = u0 * one_minus_cos_max * (2.f - u0 * one_minus_cos_max);
  const float sin2 = series ? sin2_t_exact : sin2_t;
  const float ds = dc * cos_t - safe_sqrt(r2 - dc2 * sin2);
  const float ca_raw = (dc2 + r2 - ds * ds) / (2.f * dc * radius);
  const float ca = ca_raw < -1.f ? -1.f : (1.f < ca_raw ? 1.f : ca_raw);  // std::clamp's order
  const float sa = safe_sqrt(1.f - ca * ca);
  const float lx = sa * cos_phi, ly = sa * sin_phi, lz = ca;
  // -(s x + t y + w z), normalised.
  const float mx = -((sx * lx + vx * ly) + wx * lz);
  const float my = -((sy * lx + vy * ly) + wy * lz);
  const float mz = -((sz * lx + vz * ly) + wz * lz);
  const float inv_len = 1.f / std::sqrt((mx * mx + my * my) + mz * mz);
  const float ox = mx * inv_len, oy = my * inv_len, oz = mz * inv_len;
  const float opdf = 1.f / (2.f * kPi * one_minus_cos_max);

  n[0] = inside ? ix : ox;
  n[1] = inside ? iy : oy;
  n[2] = inside ? iz : oz;
  p[0] = inside ? ipx : cx + radius * ox;
  p[1] = inside ? ipy : cy + radius * oy;
  p[2] = inside ? ipz : cz + radius * oz;
  p_error[0] = g6 * (std::fabs(cx) + std::fabs(n[0] * radius));
  p_error[1] = g6 * (std::fabs(cy) + std::fabs(n[1] * radius));
  p_error[2] = g6 * (std::fabs(cz) + std::fabs(n[2] * radius));
  *pdf = inside ? ipdf : opdf;
}

}  // namespace penumbra
