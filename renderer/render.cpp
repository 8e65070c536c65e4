#include "renderer/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <mutex>

#include "renderer/adaptive_sampling.h"
#include "renderer/film.h"
#include "renderer/integrator.h"
#include "renderer/scene_impl.h"
#include "renderer/thin_lens_camera.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

struct Tile {
  int x0, y0, x1, y1;
};

std::vector<Tile> make_tiles(int width, int height, int size) {
  std::vector<Tile> tiles;
  for (int y = 0; y < height; y += size)
    for (int x = 0; x < width; x += size)
      tiles.push_back({x, y, std::min(x + size, width), std::min(y + size, height)});
  return tiles;
}

// Sample counts of the progressive passes: 1, 1, 2, 4, 8, ... so a preview appears at once and
// each pass doubles the samples; the last pass takes what remains.
std::vector<int> make_passes(int spp) {
  std::vector<int> passes;
  int done = 0, next = 1;
  while (done < spp) {
    const int n = std::min(next, spp - done);
    passes.push_back(n);
    done += n;
    if (passes.size() > 1) next *= 2;
  }
  return passes;
}

// Adaptive sampling: re-estimates every pixel's sample limit from the samples so far.
void update_limits(const Film& film, const AdaptiveLimits& limits, std::vector<uint32_t>* out) {
  const int w = film.width(), h = film.height();
  std::vector<double> deviation(size_t(w) * h);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) deviation[size_t(y) * w + x] = film.relative_deviation(x, y);
  });
  *out = adaptive_sample_limits(deviation, w, h, limits);
}

}  // namespace

RenderResult render(const Scene& scene_handle, const RenderSettings& settings,
                    const RenderControl& control) {
  const SceneImpl& scene = scene_handle.impl();
  const auto start = Clock::now();
  const int width = settings.width, height = settings.height;
  const ThinLensCamera camera(scene.camera, width, height);
  const IntegrateFn integrate = select_integrator(settings.integrator, scene.features);
  const IntegratorSettings isettings{settings.max_depth, settings.rr_depth};
  const bool sample_lens = scene.features.lens;
  const bool sample_time = scene.features.motion;

  Film film(width, height);
  const std::vector<Tile> tiles = make_tiles(width, height, std::max(1, settings.tile_size));
  const int spp = std::max(1, settings.spp);
  const std::vector<int> passes = make_passes(spp);
  // Per pixel: samples taken so far and the most it may take. Uniform sampling keeps every limit
  // at spp; adaptive sampling (render.noise_threshold) re-estimates the limits after each pass
  // from 16 samples on (renderer/adaptive_sampling.h). Sample indices stay consecutive per pixel
  // so each pixel's samples are a prefix of its Sobol sequence.
  std::vector<uint32_t> limit(size_t(width) * height, uint32_t(spp)), taken(size_t(width) * height, 0);
  const bool adaptive = settings.noise_threshold > 0.f;
  const AdaptiveLimits adaptive_limits{settings.noise_threshold, 16, spp};

  std::atomic<uint64_t> rays{0}, samples_done{0}, nonfinite{0};
  std::atomic<bool> stop{false}, timed_out{false}, cancelled{false};
  std::mutex progress_mutex;
  uint64_t samples_total = uint64_t(width) * height * uint64_t(spp);

  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  auto make_progress = [&](int passes_done) {
    RenderProgress p;
    p.samples_total = samples_total;
    p.samples_done = samples_done.load();
    p.fraction = samples_total ? std::min(1.0, double(p.samples_done) / double(samples_total)) : 1.0;
    p.elapsed_seconds = elapsed();
    p.eta_seconds = p.fraction > 0 ? p.elapsed_seconds * (1.0 - p.fraction) / p.fraction : 0.0;
    p.passes_done = passes_done;
    return p;
  };

  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  int first_sample = 0;
  int passes_done = 0;
  for (size_t pass = 0; pass < passes.size() && !stop.load(); ++pass) {
    const int s0 = first_sample, s1 = first_sample + passes[pass];
    // Limits are decided here, between passes, so the image does not depend on threads or tile
    // order; the progress total follows them so the fraction and ETA stay meaningful.
    if (adaptive && s0 >= adaptive_limits.min_samples) {
      arena.execute([&] { update_limits(film, adaptive_limits, &limit); });
      samples_total = 0;
      for (size_t i = 0; i < limit.size(); ++i) samples_total += std::max(limit[i], taken[i]);
    }
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const auto& range) {
        for (size_t ti = range.begin(); ti != range.end(); ++ti) {
          if (stop.load(std::memory_order_relaxed)) return;
          if (control.cancel && control.cancel->load(std::memory_order_relaxed)) {
            cancelled = true;
            stop = true;
            return;
          }
          if (settings.time_limit > 0 && elapsed() >= settings.time_limit) {
            timed_out = true;
            stop = true;
            return;
          }
          const Tile& tile = tiles[ti];
          Sampler sampler(settings.seed);
          PathCounters counters;
          uint64_t tile_samples = 0, tile_nonfinite = 0;
          for (int y = tile.y0; y < tile.y1; ++y) {
            for (int x = tile.x0; x < tile.x1; ++x) {
              const size_t pi = size_t(y) * width + x;
              const uint32_t n0 = taken[pi], n1 = std::min(n0 + uint32_t(s1 - s0), limit[pi]);
              if (n0 >= n1) continue;
              taken[pi] = n1;
              for (uint32_t s = n0; s < n1; ++s) {
                sampler.start_pixel_sample(x, y, s);
                const vec2 film_pos = vec2(float(x), float(y)) + sampler.get_2d();
                const vec2 lens = sample_lens ? sampler.get_2d() : vec2(0.5f);
                const float time = sample_time ? sampler.get_1d() : 0.f;
                const CameraRay cr = camera.generate_ray(film_pos, lens, time);
                const Spectrum L =
                    integrate(scene, isettings, Ray{cr.origin, cr.direction, cr.time}, sampler, counters);
                if (!film.add_sample(x, y, L)) ++tile_nonfinite;
                ++tile_samples;
              }
            }
          }
          rays += counters.rays;
          samples_done += tile_samples;
          if (tile_nonfinite) nonfinite += tile_nonfinite;
          if (control.on_progress) {
            std::lock_guard<std::mutex> lock(progress_mutex);
            control.on_progress(make_progress(passes_done));
          }
        }
      });
    });
    if (stop.load()) break;
    first_sample = s1;
    ++passes_done;
    if (control.on_pass) control.on_pass(film.resolve(), make_progress(passes_done));
  }

  RenderResult result;
  result.image = film.resolve();
  result.variance = film.resolve_variance();
  RenderStats& st = result.stats;
  st.seconds = elapsed();
  st.rays = rays.load();
  st.camera_samples = samples_done.load();
  st.cancelled = cancelled.load();
  st.stopped_by_time_limit = timed_out.load();
  st.nonfinite_samples = nonfinite.load();
  uint32_t lo = UINT32_MAX, hi = 0;
  double sum = 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const uint32_t n = film.samples(x, y);
      lo = std::min(lo, n);
      hi = std::max(hi, n);
      sum += n;
    }
  st.spp_min = int(lo == UINT32_MAX ? 0 : lo);
  st.spp_max = int(hi);
  st.spp_mean = width * height > 0 ? sum / (double(width) * height) : 0.0;
  return result;
}

}  // namespace penumbra
