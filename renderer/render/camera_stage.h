#pragma once
// The wavefront driver's camera stage: a batch's camera samples queued, then their sampler
// dimensions (sobol_batch.h) and rays (ThinLensCamera::generate_rays) computed for all of them
// at once, and handed to the PathBatch. Per sample the values and rays are those of the scalar
// loop's start_pixel_sample, take_camera_sample (camera_sample.h), generate_ray, to the bit.
#include <cstdint>
#include <vector>

#include "renderer/render/camera_sample.h"
#include "renderer/render/thin_lens_camera.h"
#include "renderer/render/wavefront_integrator.h"
#include "renderer/sampling/sobol_batch.h"

namespace penumbra {

class CameraStage {
 public:
  CameraStage(const ThinLensCamera& camera, bool sample_lens, bool sample_time, size_t capacity);

  // Samples first, first + 1, ..., first + count - 1 of image pixel (x, y), with `sampler` on
  // that pixel. Queued as one run: the stage takes a run's sampler seeds, film offsets and
  // paths together (a queue entry per sample, written here and read back three times, was 30%
  // of the stage's instructions on the furnace: docs/performance.md, levers, session 37).
  void add_run(Sampler* sampler, int x, int y, uint32_t first, uint32_t count) {
    if (count == 0) return;
    runs_.push_back(Run{sampler, x, y, first, count});
    queued_ += count;
  }
  size_t size() const { return queued_; }
  // The queued samples' camera rays into `batch`, in the order they were queued; then empty.
  void generate(PathBatch& batch);

 private:
  struct Run {
    Sampler* sampler;
    int x, y;
    uint32_t first, count;
  };
  const ThinLensCamera& camera_;
  bool sample_lens_, sample_time_;
  std::vector<Run> runs_;
  size_t queued_ = 0;  // samples in all runs
  BounceSamples samples_;
  std::vector<float> film_x_, film_y_, lens_x_, lens_y_, time_, rays_[6];
};

}  // namespace penumbra
