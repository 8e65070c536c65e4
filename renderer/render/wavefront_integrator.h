#pragma once
// The wavefront driver of the integrators: a batch of camera samples advanced together a bounce
// at a time (pbrt-v4's wavefront integrator and Mitsuba 3's LLVM mode are the models). Each
// bounce traces all live paths' rays in 16-wide Embree packets (camera rays as coherent ones),
// shades every path with the same steps as the scalar driver (path_step.h), then traces the
// bounce's shadow rays in packets. Paths on plain Lambertian surfaces and rough conductors take
// their step together in SIMD lanes, one stage per model (surface_stage.h). Per path the steps, sampler dimensions and additions are the
// scalar driver's, so both give the same image; only the order paths are advanced in differs.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "renderer/render/path_reuse.h"
#include "renderer/render/surface_stage.h"
#include "renderer/render/path_step.h"
#include "renderer/sampling/sobol_batch.h"

namespace penumbra {

class PathBatch {
 public:
  // Room for `capacity` paths (more grow it).
  explicit PathBatch(size_t capacity, bool record_first_hits);

  size_t size() const { return size_; }
  bool full() const { return size_ >= capacity_; }
  void clear() { size_ = 0; }
  // A camera stage's run of `count` samples of one pixel: sample first + j's ray from the arrays'
  // entry j (origin, direction and time; no t_max), its pixel's sampler, and its cursor after
  // the `dimensions` the camera took. The sampler must stay on that pixel until the batch is
  // integrated (the run's samples share it). The per-path arrays keep their capacity's
  // elements, so a run is assigned in place, each field once in one loop (appended, each of four
  // arrays checked its capacity per sample: 1.5% of the furnace's render, docs/performance.md,
  // session 36).
  void add_camera_run(size_t count, const float* const rays[6], const float* time, Sampler* sampler,
                      uint32_t first, uint64_t dimensions) {
    while (capacity_ - size_ < count) grow();
    PathState* __restrict states = states_.data() + size_;
    Sampler** __restrict samplers = samplers_.data() + size_;
    Sampler::Cursor* __restrict cursors = cursors_.data() + size_;
    for (size_t j = 0; j < count; ++j) {
      states[j] = PathState(Ray{vec3(rays[0][j], rays[1][j], rays[2][j]),
                                vec3(rays[3][j], rays[4][j], rays[5][j]), time[j]});
      samplers[j] = sampler;
      cursors[j] = Sampler::Cursor{first + uint32_t(j), dimensions};
    }
    if (record_first_hits_) std::fill_n(firsts_.data() + size_, count, FirstHit{});
    size_ += count;
  }

  // After integrate: the path's radiance and, if recorded, its camera ray's first hit.
  const Spectrum& radiance(size_t i) const { return states_[i].radiance; }
  const FirstHit& first_hit(size_t i) const { return firsts_[i]; }
  // Path reuse (path_reuse.h): whether integrate records each path's first two vertices, and,
  // after integrate, their records and the paths' states to reuse them in place.
  void set_reuse(bool on) {
    reuse_on_ = on;
    if (on) reuse_.resize(capacity_);
  }
  const ReuseRecord* reuse_records() const { return reuse_.data(); }
  PathState* states() { return states_.data(); }

  template <bool, uint32_t>
  friend void integrate_batch(const Scene&, const IntegratorSettings&, PathBatch&, PathCounters&);
  friend void make_stages(const Scene& scene, PathBatch& b);

 private:
  void grow();  // twice the capacity
  void size_arrays();

  size_t capacity_;
  bool record_first_hits_;
  size_t size_ = 0;  // paths in the batch: the first size_ elements of the per-path arrays
  std::vector<PathState> states_;
  std::vector<Sampler*> samplers_;
  std::vector<Sampler::Cursor> cursors_;
  std::vector<FirstHit> firsts_;
  bool reuse_on_ = false;
  std::vector<ReuseRecord> reuse_;  // per path, when reuse_on_
  // Scratch of one bounce: the live paths, their hits, and the shadow queries with their paths.
  std::vector<uint32_t> live_;
  std::vector<SurfaceHit> hits_;
  std::vector<uint8_t> found_;
  std::vector<ShadowQuery> shadows_;
  std::vector<uint32_t> shadow_paths_, shadow_slots_;
  BounceSamples samples_;  // the sampler values of the bounce's paths that hit something
  // Made for the scene at hand: the stages of the models its surfaces use.
  const Scene* staged_scene_ = nullptr;
  std::vector<std::unique_ptr<SurfaceStage>> stages_;
  std::vector<int8_t> stage_of_;  // per object: its stage in stages_, or -1
  // Per stage, the slots of the bounce's paths it takes, in path order (SurfaceStage::add_many
  // finds each one's path, hit and sampler column from its slot).
  using StageQueue = std::vector<uint32_t>;
  std::vector<StageQueue> queues_;
  bool lobe_choices_ = true;      // whether a surface of the scene may pick among lobes
  bool roulette_at_lobe_ = true;  // whether a step may read a bounce's lobe dimension as a 1D value
  std::vector<uint8_t> goes_on_, has_shadow_;  // per live path of the bounce
  std::vector<uint32_t> hit_of_;               // per live path: its index among the hits
  std::vector<uint32_t> hit_slots_, miss_slots_;  // the live paths' slots with a hit, without
  std::vector<uint32_t> unstaged_;  // a stage's lanes whose parameters leave its model
  // The bounce's escaped paths that ask the environment, their directions, whether each wants
  // the pdf, and the answers (EnvironmentLight::radiance_and_pdf_many).
  std::vector<uint32_t> escaped_;
  std::vector<vec3> escaped_dirs_;
  std::vector<uint8_t> escaped_want_pdf_;
  std::vector<Spectrum> escaped_radiance_;
  std::vector<float> escaped_pdf_;
};

using IntegrateBatchFn = void (*)(const Scene& scene, const IntegratorSettings& settings,
                                  PathBatch& batch, PathCounters& counters);

// As select_integrator (integrator.h): specialised on the scene's features.
IntegrateBatchFn select_batch_integrator(IntegratorKind kind, const SceneFeatures& features);
IntegrateBatchFn select_generic_batch_integrator(IntegratorKind kind);

}  // namespace penumbra
