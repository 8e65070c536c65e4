#include "renderer/render/camera_stage.h"

namespace penumbra {

CameraStage::CameraStage(const ThinLensCamera& camera, bool sample_lens, bool sample_time,
                         size_t capacity)
    : camera_(camera), sample_lens_(sample_lens), sample_time_(sample_time) {
  queued_.reserve(capacity);
  for (auto* v : {&film_x_, &film_y_, &lens_x_, &lens_y_, &time_}) v->resize(capacity);
  for (auto& v : rays_) v.resize(capacity);
  cursors_.resize(capacity);
}

void CameraStage::generate(PathBatch& batch) {
  const size_t n = queued_.size();
  if (n > film_x_.size()) {
    for (auto* v : {&film_x_, &film_y_, &lens_x_, &lens_y_, &time_}) v->resize(n);
    for (auto& v : rays_) v.resize(n);
    cursors_.resize(n);
  }
  // The camera's dimensions, in the scalar loop's order: film, lens, time.
  const int dims = 1 + int(sample_lens_) + int(sample_time_);
  samples_.start(n, dims);
  for (const Queued& q : queued_) samples_.add(*q.sampler, Sampler::Cursor{q.index, 0});
  samples_.compute();
  for (size_t i = 0; i < n; ++i) {
    const Queued& q = queued_[i];
    PrefetchedSampler sampler(*q.sampler, Sampler::Cursor{q.index, 0}, samples_, i);
    const vec2 film = vec2(float(q.x), float(q.y)) + sampler.get_2d();
    film_x_[i] = film.x;
    film_y_[i] = film.y;
    const vec2 lens = sample_lens_ ? sampler.get_2d() : vec2(0.5f);
    lens_x_[i] = lens.x;
    lens_y_[i] = lens.y;
    time_[i] = sample_time_ ? sampler.get_1d() : 0.f;
    cursors_[i] = sampler.cursor();
  }
  float* const out[6] = {rays_[0].data(), rays_[1].data(), rays_[2].data(),
                         rays_[3].data(), rays_[4].data(), rays_[5].data()};
  camera_.generate_rays(n, film_x_.data(), film_y_.data(), lens_x_.data(), lens_y_.data(), out);
  for (size_t i = 0; i < n; ++i) {
    const Ray ray{vec3(rays_[0][i], rays_[1][i], rays_[2][i]),
                  vec3(rays_[3][i], rays_[4][i], rays_[5][i]), time_[i]};
    batch.add(ray, queued_[i].sampler, cursors_[i]);
  }
  queued_.clear();
}

}  // namespace penumbra
