#pragma once
// The render loop: tiles on a thread pool, progressive passes, cancellation and time budget.
#include <atomic>
#include <cstdint>
#include <functional>

#include "renderer/core/image.h"
#include "renderer/scene/scene.h"

namespace penumbra {

struct RenderProgress {
  double fraction = 0.0;          // 0..1 of the planned samples
  uint64_t samples_done = 0;      // camera samples taken so far (all pixels)
  uint64_t samples_total = 0;
  double elapsed_seconds = 0.0;
  double eta_seconds = 0.0;
  int passes_done = 0;
};

struct RenderControl {
  // Polled between tiles: set it and the render stops within about one tile's time.
  const std::atomic<bool>* cancel = nullptr;
  // Called from render threads (serialised) after every finished tile; keep it cheap.
  std::function<void(const RenderProgress&)> on_progress;
  // Called after every finished pass with the current resolved image (progressive preview).
  std::function<void(const Image&, const RenderProgress&)> on_pass;
  // Where previews or a time budget make progressive passes: after the first pass (one sample
  // per pixel, the first preview at once) each pass takes at least about this long at the
  // previous pass's rate, or doubles the samples so far if that is more (pass_plan.h). Previews
  // then come about this often at first (the service's clients poll every 1-1.5 s), and a short
  // render is not cut into passes of 1, 1, 2, 4, ... samples, each a boundary that costs time.
  // 0: the sizes just double (1, 1, 2, 4, ...).
  double min_pass_seconds = 0.5;
};

struct RenderStats {
  double seconds = 0.0;
  uint64_t rays = 0;             // every ray traced: camera, bounce and shadow rays
  uint64_t camera_samples = 0;
  int spp_min = 0;               // samples in the least-sampled pixel
  int spp_max = 0;
  double spp_mean = 0.0;
  bool cancelled = false;
  bool stopped_by_time_limit = false;
  uint64_t nonfinite_samples = 0;  // dropped samples that evaluated to NaN/Inf (should stay 0)
  // RenderSettings::denoise: whether the image is the denoised one, the denoiser's seconds
  // (within `seconds`), and why it is not (OIDN missing or failing: the image stays as rendered).
  bool denoised = false;
  double denoise_seconds = 0.0;
  std::string denoise_error;
  double mrays_per_second() const { return seconds > 0 ? rays / seconds * 1e-6 : 0.0; }
};

struct RenderResult {
  // The pixels of the settings' width x height image that image, variance and layers hold: the
  // settings' window, else the whole image. Statistics count these pixels only.
  PixelWindow window;
  Image image;     // mean radiance per pixel
  Image variance;  // per pixel and channel: estimated variance of that mean (sample variance / n)
  // The output layers RenderSettings::outputs asked for, in OutputLayerBit order (empty if none),
  // then, when denoised, the image as rendered ("noisy", kNoisyLayerName).
  std::vector<ImageLayer> layers;
  RenderStats stats;
};

// Deterministic: for a given scene, settings and seed, the image does not depend on the number
// of threads or the tile size.
RenderResult render(const Scene& scene, const RenderSettings& settings,
                    const RenderControl& control = {});

// The sampler's points for these settings (the Sampler's cmj_bits, 0 for Sobol points):
// correlated multi-jittered ones when spp is a power of two, unless settings.sampler asks for
// Sobol points or adaptive sampling needs them (renderer/sampling/cmj.h).
uint32_t sampler_cmj_bits(const RenderSettings& settings);

}  // namespace penumbra
