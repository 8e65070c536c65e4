#include "renderer/render/thin_lens_camera.h"

#include "renderer/sampling/sampling.h"

namespace penumbra {

ThinLensCamera::ThinLensCamera(const CameraDesc& desc, int width, int height)
    : position_(desc.position),
      aperture_radius_(desc.aperture_radius),
      focus_distance_(desc.focus_distance),
      width_(width),
      height_(height) {
  forward_ = glm::normalize(desc.look_at - desc.position);
  right_ = glm::normalize(glm::cross(forward_, desc.up));
  up_ = glm::cross(right_, forward_);
  tan_half_fov_ = std::tan(glm::radians(desc.fov_degrees) * 0.5f);
  aspect_ = float(width) / float(height);
}

CameraRay ThinLensCamera::generate_ray(const vec2& film, const vec2& lens, float time) const {
  const float sx = (2.f * film.x / float(width_) - 1.f) * tan_half_fov_ * aspect_;
  const float sy = (1.f - 2.f * film.y / float(height_)) * tan_half_fov_;
  // Direction to the image plane at unit distance along the optical axis.
  const vec3 d = forward_ + sx * right_ + sy * up_;
  if (aperture_radius_ <= 0.f) return {position_, glm::normalize(d), time};
  // Thin lens: every ray through the lens converges on the plane of focus, which lies at
  // focus_distance along the optical axis (so d's axial component 1 scales directly).
  const vec3 focus_point = position_ + d * focus_distance_;
  const vec2 disk = square_to_disk_concentric(lens) * aperture_radius_;
  const vec3 origin = position_ + disk.x * right_ + disk.y * up_;
  return {origin, glm::normalize(focus_point - origin), time};
}

}  // namespace penumbra
