#include "renderer/render/camera_stage.h"

#include <algorithm>

namespace penumbra {

CameraStage::CameraStage(const ThinLensCamera& camera, bool sample_lens, bool sample_time,
                         size_t capacity)
    : camera_(camera), sample_lens_(sample_lens), sample_time_(sample_time) {
  runs_.reserve(capacity);
}

void CameraStage::generate(PathBatch& batch) {
  const size_t n = queued_;
  if (n > film_x_.size()) {  // the arrays grow to the largest batch once
    for (auto* v : {&film_x_, &film_y_, &time_}) v->resize(n);
    // Without a lens sample generate_rays is given the lens centre; without motion the time is
    // 0: set here once, never overwritten (sample_lens_ and sample_time_ are the stage's own).
    lens_x_.resize(n, 0.5f);
    lens_y_.resize(n, 0.5f);
    for (auto& v : rays_) v.resize(n);
  }
  // The camera's dimensions in take_camera_sample's order (camera_sample.h); with motion the
  // time is the 1D value of the film's pair.
  const int dims = camera_sample_dimensions(sample_lens_, sample_time_);
  const uint32_t pair = sample_time_ ? 1u << kCameraTimeDimension : 0u;
  samples_.start(n, dims, pair, pair);
  for (const Run& r : runs_) samples_.add_run(*r.sampler, r.first, r.count, 0);
  samples_.compute();
  const int film_dim = camera_film_dimension(sample_time_), lens_dim = camera_lens_dimension(sample_time_);
  const float* film_u = samples_.dimension_x(film_dim);
  const float* film_v = samples_.dimension_y(film_dim);
  // take_camera_sample's film position plus the pixel, vec2(x, y) + (u, v).
  for (size_t i = 0; const Run& r : runs_) {
    const float x = float(r.x), y = float(r.y);
    for (size_t j = i; j < i + r.count; ++j) {
      film_x_[j] = x + film_u[j];
      film_y_[j] = y + film_v[j];
    }
    i += r.count;
  }
  if (sample_lens_) {
    std::copy_n(samples_.dimension_x(lens_dim), n, lens_x_.data());
    std::copy_n(samples_.dimension_y(lens_dim), n, lens_y_.data());
  }
  if (sample_time_) std::copy_n(samples_.z(0), n, time_.data());
  float* const out[6] = {rays_[0].data(), rays_[1].data(), rays_[2].data(),
                         rays_[3].data(), rays_[4].data(), rays_[5].data()};
  camera_.generate_rays(n, film_x_.data(), film_y_.data(), lens_x_.data(), lens_y_.data(), out);
  for (size_t i = 0; const Run& r : runs_) {
    const float* const rays[6] = {rays_[0].data() + i, rays_[1].data() + i, rays_[2].data() + i,
                                  rays_[3].data() + i, rays_[4].data() + i, rays_[5].data() + i};
    batch.add_camera_run(r.count, rays, time_.data() + i, r.sampler, r.first, uint64_t(dims));
    i += r.count;
  }
  runs_.clear();
  queued_ = 0;
}

}  // namespace penumbra
