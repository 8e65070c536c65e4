// The camera stage of the wavefront driver: a batch's camera rays from arrays, in SIMD lanes.
// A pinhole ray is a dozen multiplies and adds, a division and a square root in one dependent
// chain; one sample at a time the CPU waits on it, over arrays eight or sixteen go at once.
// The arithmetic is generate_ray's, operation for operation: IEEE add, multiply, divide and
// square root round the same in a lane as in a scalar register, and this file and
// thin_lens_camera.cpp are compiled without contraction into fused multiply-adds
// (-ffp-contract=off, renderer/CMakeLists.txt), so the rays are the scalar ones to the bit.
#include <cmath>

#include "renderer/core/simd_clones.h"
#include "renderer/materials/lane_microfacet.h"
#include "renderer/render/thin_lens_camera.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {
namespace {

struct CameraFrame {
  float px, py, pz, rx, ry, rz, ux, uy, uz, fx, fy, fz;
  float tan_half_fov, aspect, width, height;
};

// The image-plane direction of generate_ray: forward + sx right + sy up.
[[gnu::always_inline]] inline void plane_direction(const CameraFrame& c, float film_x, float film_y,
                                                   float* dx, float* dy, float* dz) {
  const float sx = (2.f * film_x / c.width - 1.f) * c.tan_half_fov * c.aspect;
  const float sy = (1.f - 2.f * film_y / c.height) * c.tan_half_fov;
  *dx = (c.fx + sx * c.rx) + sy * c.ux;
  *dy = (c.fy + sx * c.ry) + sy * c.uy;
  *dz = (c.fz + sx * c.rz) + sy * c.uz;
}

// glm::normalize(v) = v * (1 / sqrt(dot(v, v))), dot summed x, y, z in that order.
[[gnu::always_inline]] inline void normalize_into(float x, float y, float z, float* ox, float* oy,
                                                  float* oz) {
  const float inv = 1.f / std::sqrt((x * x + y * y) + z * z);
  *ox = x * inv;
  *oy = y * inv;
  *oz = z * inv;
}

PENUMBRA_SIMD_CLONES
void pinhole_rays(const CameraFrame& c, size_t n, const float* __restrict film_x,
                  const float* __restrict film_y, float* __restrict dx, float* __restrict dy,
                  float* __restrict dz) {
  for (size_t i = 0; i < n; ++i) {
    float x, y, z;
    plane_direction(c, film_x[i], film_y[i], &x, &y, &z);
    normalize_into(x, y, z, &dx[i], &dy[i], &dz[i]);
  }
}

// Thin lens: the lens sample (lens_x, lens_y) goes to the disk by the concentric map (its two
// wedges as selects, lane::disk_concentric) scaled by the aperture, as generate_ray takes it; the
// ray runs from there through the point of focus.
PENUMBRA_SIMD_CLONES
void lens_rays(const CameraFrame& c, float focus_distance, float aperture_radius, size_t n,
               const float* __restrict film_x, const float* __restrict film_y,
               const float* __restrict lens_x, const float* __restrict lens_y, float* __restrict ox,
               float* __restrict oy, float* __restrict oz, float* __restrict dx, float* __restrict dy,
               float* __restrict dz) {
  for (size_t i = 0; i < n; ++i) {
    float x, y, z;
    plane_direction(c, film_x[i], film_y[i], &x, &y, &z);
    float disk_x, disk_y;
    lane::disk_concentric(lens_x[i], lens_y[i], &disk_x, &disk_y);
    disk_x *= aperture_radius;
    disk_y *= aperture_radius;
    const float focus_x = c.px + x * focus_distance, focus_y = c.py + y * focus_distance,
                focus_z = c.pz + z * focus_distance;
    const float o_x = (c.px + disk_x * c.rx) + disk_y * c.ux;
    const float o_y = (c.py + disk_x * c.ry) + disk_y * c.uy;
    const float o_z = (c.pz + disk_x * c.rz) + disk_y * c.uz;
    ox[i] = o_x;
    oy[i] = o_y;
    oz[i] = o_z;
    normalize_into(focus_x - o_x, focus_y - o_y, focus_z - o_z, &dx[i], &dy[i], &dz[i]);
  }
}

}  // namespace

void ThinLensCamera::generate_rays(size_t n, const float* film_x, const float* film_y,
                                   const float* lens_x, const float* lens_y,
                                   float* const out[6]) const {
  const CameraFrame c{position_.x, position_.y, position_.z, right_.x, right_.y, right_.z,
                      up_.x,       up_.y,       up_.z,       forward_.x, forward_.y, forward_.z,
                      tan_half_fov_, aspect_, float(width_), float(height_)};
  if (aperture_radius_ <= 0.f) {
    for (size_t i = 0; i < n; ++i) {
      out[0][i] = position_.x;
      out[1][i] = position_.y;
      out[2][i] = position_.z;
    }
    pinhole_rays(c, n, film_x, film_y, out[3], out[4], out[5]);
    return;
  }
  lens_rays(c, focus_distance_, aperture_radius_, n, film_x, film_y, lens_x, lens_y, out[0], out[1], out[2],
            out[3], out[4], out[5]);
}

}  // namespace penumbra
