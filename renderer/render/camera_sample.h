#pragma once
// A camera sample's sampler values, taken from the pixel's sampler in one order that the scalar
// loop (render.cpp), the wavefront's CameraStage and the tests share.
//
// Without motion: film position (2D), then lens (2D) where the camera has an aperture. With
// motion the shutter time comes first, as the 1D value of one 3D point with the film position
// (Sampler::get_1d_2d): which part of the pixel a moving edge covers depends on both, and a
// (1, m, 3)-net stratifies their joint distribution where separately scrambled 1D and 2D points
// pair at random. The count of dimensions is the same either way (2 or 3 with the lens).
#include "renderer/core/math.h"
#include "renderer/sampling/sampler.h"

namespace penumbra {

struct CameraSample {
  vec2 film;  // in [0, 1)^2 within the pixel
  vec2 lens;  // (0.5, 0.5) without an aperture
  float time;  // 0 without motion
};

// The dimensions a camera sample takes: film, lens and time, time sharing film's pair.
inline int camera_sample_dimensions(bool sample_lens, bool sample_time) {
  return 1 + int(sample_time) + int(sample_lens);
}
// Where they are among them (CameraStage reads prefetched values by these).
constexpr int kCameraTimeDimension = 0;  // with motion: the pair's 1D value
inline int camera_film_dimension(bool sample_time) { return sample_time ? 1 : 0; }
inline int camera_lens_dimension(bool sample_time) { return sample_time ? 2 : 1; }

inline CameraSample take_camera_sample(Sampler& sampler, bool sample_lens, bool sample_time) {
  CameraSample s{vec2(0.f), vec2(0.5f), 0.f};
  if (sample_time)
    sampler.get_1d_2d(&s.time, &s.film);
  else
    s.film = sampler.get_2d();
  if (sample_lens) s.lens = sampler.get_2d();
  return s;
}

}  // namespace penumbra
