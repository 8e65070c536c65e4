#pragma once
// Perspective camera with a thin lens (Cook, Porter & Carpenter 1984) and a shutter interval.
#include "renderer/core/math.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

struct CameraRay {
  vec3 origin;
  vec3 direction;  // unit
  float time;      // normalised shutter time in [0,1]
};

class ThinLensCamera {
 public:
  ThinLensCamera(const CameraDesc& desc, int width, int height);

  // film: continuous pixel coordinates (x right, y down, [0,w)x[0,h)); lens, time: in [0,1).
  CameraRay generate_ray(const vec2& film, const vec2& lens, float time) const;
  // generate_ray's origins and directions for n samples at once, to the bit (camera_batch.cpp):
  // film positions (film_x, film_y), lens samples (lens_x, lens_y; ignored without an
  // aperture); origin and direction components into out[0..5][i].
  void generate_rays(size_t n, const float* film_x, const float* film_y, const float* lens_x,
                     const float* lens_y, float* const out[6]) const;
  // The centre of the lens and the unit optical axis (z-depth is measured along it).
  const vec3& position() const { return position_; }
  const vec3& forward() const { return forward_; }


 private:
  vec3 position_, right_, up_, forward_;
  float tan_half_fov_, aspect_;
  float aperture_radius_, focus_distance_;
  int width_, height_;
};

}  // namespace penumbra
