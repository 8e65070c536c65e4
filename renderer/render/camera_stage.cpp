#include "renderer/render/camera_stage.h"

#include <algorithm>

namespace penumbra {

CameraStage::CameraStage(const ThinLensCamera& camera, bool sample_lens, bool sample_time,
                         size_t capacity)
    : camera_(camera), sample_lens_(sample_lens), sample_time_(sample_time) {
  queued_.reserve(capacity);
}

void CameraStage::generate(PathBatch& batch) {
  const size_t n = queued_.size();
  if (n > film_x_.size()) {  // the arrays grow to the largest batch once
    for (auto* v : {&film_x_, &film_y_, &lens_x_, &lens_y_, &time_}) v->resize(n);
    for (auto& v : rays_) v.resize(n);
  }
  // The camera's dimensions in take_camera_sample's order (camera_sample.h); with motion the
  // time is the 1D value of the film's pair.
  const int dims = camera_sample_dimensions(sample_lens_, sample_time_);
  const uint32_t pair = sample_time_ ? 1u << kCameraTimeDimension : 0u;
  samples_.start(n, dims, pair, pair);
  for (const Queued& q : queued_) samples_.add(*q.sampler, Sampler::Cursor{q.index, 0});
  samples_.compute();
  const int film_dim = camera_film_dimension(sample_time_), lens_dim = camera_lens_dimension(sample_time_);
  const float* film_u = samples_.dimension_x(film_dim);
  const float* film_v = samples_.dimension_y(film_dim);
  for (size_t i = 0; i < n; ++i) {
    const Queued& q = queued_[i];
    const vec2 film = vec2(float(q.x), float(q.y)) + vec2(film_u[i], film_v[i]);
    film_x_[i] = film.x;
    film_y_[i] = film.y;
  }
  if (sample_lens_) {
    std::copy_n(samples_.dimension_x(lens_dim), n, lens_x_.data());
    std::copy_n(samples_.dimension_y(lens_dim), n, lens_y_.data());
  } else {
    std::fill_n(lens_x_.data(), n, 0.5f);
    std::fill_n(lens_y_.data(), n, 0.5f);
  }
  if (sample_time_)
    std::copy_n(samples_.z(0), n, time_.data());
  else
    std::fill_n(time_.data(), n, 0.f);
  float* const out[6] = {rays_[0].data(), rays_[1].data(), rays_[2].data(),
                         rays_[3].data(), rays_[4].data(), rays_[5].data()};
  camera_.generate_rays(n, film_x_.data(), film_y_.data(), lens_x_.data(), lens_y_.data(), out);
  for (size_t i = 0; i < n; ++i) {
    const Ray ray{vec3(rays_[0][i], rays_[1][i], rays_[2][i]),
                  vec3(rays_[3][i], rays_[4][i], rays_[5][i]), time_[i]};
    batch.add(ray, queued_[i].sampler, Sampler::Cursor{queued_[i].index, uint64_t(dims)});
  }
  queued_.clear();
}

}  // namespace penumbra
