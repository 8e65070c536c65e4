#include "renderer/render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <numeric>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "renderer/core/flush_denormals.h"
#include "renderer/render/adaptive_sampling.h"
#include "renderer/render/film.h"
#include "renderer/render/integrator.h"
#include "renderer/denoise/denoise_result.h"
#include "renderer/render/output_layers.h"
#include "renderer/render/pass_plan.h"
#include "renderer/render/path_reuse.h"
#include "renderer/render/camera_sample.h"
#include "renderer/render/camera_stage.h"
#include "renderer/render/thin_lens_camera.h"
#include "renderer/render/wavefront_integrator.h"
#include "renderer/sampling/cmj.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

// Camera samples the wavefront driver advances together: enough to fill its 16-wide packets
// for several bounces as paths end and to spread each bounce's fixed costs, few enough that
// their state stays in cache. Measured side by side (bench/pair_renders.sh): 512 against 256
// 0.96-0.98 of the time on every scene tried (session 32), 1024 against 512 0.93-1.00 on the
// sixteen other scenes and 1.006-1.013 on mesh_100k, 2048 against 1024 1.00-1.05
// (docs/performance.md, levers, sessions 32 and 33).
constexpr size_t kWavefrontBatch = 1024;

// The rendered pixels tile by tile (row-major inside each tile), and where each tile starts in
// that order: a pass's work items are ranges of it. Indices are into the film, which covers the
// render's window (the whole image without one).
struct PixelOrder {
  std::vector<uint32_t> pixels;
  std::vector<size_t> tile_starts;  // one per tile, plus the end
};

// With path reuse (block > 1) a tile's pixels go block by block (row-major inside each
// block), so a reuse group's pixels are consecutive.
PixelOrder make_pixel_order(int width, int height, int size, int block) {
  PixelOrder o;
  for (int y0 = 0; y0 < height; y0 += size)
    for (int x0 = 0; x0 < width; x0 += size) {
      o.tile_starts.push_back(o.pixels.size());
      const int y1 = std::min(y0 + size, height), x1 = std::min(x0 + size, width);
      for (int by = y0; by < y1; by += block)
        for (int bx = x0; bx < x1; bx += block)
          for (int y = by; y < std::min(by + block, y1); ++y)
            for (int x = bx; x < std::min(bx + block, x1); ++x) o.pixels.push_back(uint32_t(y * width + x));
    }
  o.tile_starts.push_back(o.pixels.size());
  return o;
}

// Work items of a pass: consecutive ranges of the pixel order holding about equal numbers of
// samples. An adaptive pass needs them once limits differ: the samples of a pass crowd into the
// few tiles where the noise is, and tile-sized items would leave threads idle at the pass's end.
// A pass where every pixel takes the same samples needs them where several threads share fewer
// tiles than kItemsPerThread each: a thread that runs out of items waits for the other's last
// one, and the accuracy scenes' 64 x 64 images are 16 tiles of very unequal cost (a sphere's
// tiles against the sky's); with 64-pixel items instead, two threads take 0.95-1.00 of the time
// (instances 0.95, plastics and kitchen_sink 0.96, conductors 0.96, none slower;
// docs/performance.md, levers, session 30). One thread keeps the tiles: nothing to balance.
constexpr int kItemsPerThread = 32;
std::vector<size_t> balanced_items(const PixelOrder& order, const std::vector<uint32_t>& taken,
                                   const std::vector<uint32_t>& limit, uint32_t pass_samples,
                                   int parts) {
  auto work = [&](uint32_t p) {
    return limit[p] > taken[p] ? std::min(pass_samples, limit[p] - taken[p]) : 0u;
  };
  uint64_t total = 0;
  for (uint32_t p : order.pixels) total += work(p);
  const uint64_t per_item = std::max<uint64_t>(1, total / uint64_t(std::max(1, parts)));
  std::vector<size_t> starts{0};
  uint64_t acc = 0;
  for (size_t k = 0; k < order.pixels.size(); ++k) {
    acc += work(order.pixels[k]);
    if (acc >= per_item && k + 1 < order.pixels.size()) {
      starts.push_back(k + 1);
      acc = 0;
    }
  }
  starts.push_back(order.pixels.size());
  return starts;
}

// A render thread's wavefront driver state between work items: the batch (with the surface
// stages it makes for the scene), the camera stage, and the batch's per-pixel samplers and pixel
// indices (the samplers reserved to the batch's capacity: the camera stage keeps pointers to them).
struct WavefrontScratch {
  PathBatch batch;
  CameraStage camera_stage;
  std::vector<Sampler> samplers;
  std::vector<uint32_t> batch_pixels;
  // With path reuse: per path its group's key (block, sample index), and the grouping.
  std::vector<uint64_t> batch_keys;
  std::vector<uint32_t> grouped;
  std::vector<size_t> group_starts;
  WavefrontScratch(const ThinLensCamera& camera, bool sample_lens, bool sample_time, bool first_hits)
      : batch(kWavefrontBatch, first_hits),
        camera_stage(camera, sample_lens, sample_time, kWavefrontBatch) {
    samplers.reserve(kWavefrontBatch);
    batch_pixels.reserve(kWavefrontBatch);
  }
};

// The render's passes (pass_plan.h). Where nothing asks for a boundary they start at the first
// one that is needed: all samples at once for uniform sampling, min_samples for adaptive
// sampling, whose limits are then decided after the same sample counts (16, 32, 64, ...) and so
// are the same. A preview or a time budget wants a first pass of one sample (a first image at
// once; a budget cut then leaves every pixel sampled), then passes of at least
// control.min_pass_seconds (uniform renders of the accuracy scenes in one pass instead of 1, 1,
// 2, 4, ..., two threads: 0.80-0.99 of the time at 64 spp, 0.91-0.96 at 256; docs/performance.md,
// levers). Per pixel the samples and their order in the film are the same whatever the passes,
// so the image is the same bit for bit.
PassPlan plan_passes(const RenderSettings& settings, const RenderControl& control, bool adaptive,
                     int min_samples) {
  PassPlan plan;
  plan.spp = std::max(1, settings.spp);
  const bool progressive = control.on_pass || settings.time_limit > 0;
  plan.first = progressive ? 1 : adaptive ? min_samples : plan.spp;
  plan.fixed_from = adaptive ? min_samples : INT_MAX;
  plan.min_seconds = progressive ? std::max(0.0, control.min_pass_seconds) : 0.0;
  return plan;
}

// Adaptive sampling: re-estimates every pixel's sample limit from the samples so far. With a
// window the film is the window: the allocation's mean and the 3x3 neighbourhoods are taken over
// its pixels alone, so a window's limits never depend on pixels another machine renders (each
// window aims at the threshold by itself; docs/animation-and-windows.md).
void update_limits(const Film& film, const AdaptiveLimits& limits, std::vector<uint32_t>* out) {
  const int w = film.width(), h = film.height();
  std::vector<double> deviation(size_t(w) * h);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) deviation[size_t(y) * w + x] = film.relative_deviation(x, y);
  });
  *out = adaptive_sample_limits(deviation, w, h, limits);
}

}  // namespace

// Correlated multi-jittered points where every pixel takes spp samples, a power of two (less
// variance at equal samples on most scenes: docs/performance.md, levers, session 38); Sobol
// points where asked for and with adaptive sampling, whose pixels take prefixes of their samples
// that must each be well stratified. A time budget does not decide it here: a service's cap on
// render time must not change a job's image (api/ gives a scene's own budget Sobol points).
uint32_t sampler_cmj_bits(const RenderSettings& settings) {
  if (settings.noise_threshold > 0.f || settings.sampler == SamplerKind::kSobol) return 0u;
  // At other counts a pixel would take a prefix of a larger pattern, which has more variance
  // than the Sobol points (cornell 1.13 at 48 and 100 spp, mesh_files 1.31 and 1.21).
  const uint32_t spp = uint32_t(std::max(1, settings.spp));
  return cmj_takes_count(spp) ? cmj_bits_for(spp) : 0u;
}

RenderResult render(const Scene& scene, const RenderSettings& settings,
                    const RenderControl& control) {
  scene.prepare_sampling(settings.integrator);  // (done already if the caller timed it as build)
  const auto start = Clock::now();
  // The camera sees the whole image; the films hold only the window's pixels, film pixel
  // (fx, fy) being image pixel (window.x0 + fx, window.y0 + fy). The sampler and the camera are
  // keyed on image coordinates, so a pixel's samples do not depend on the window.
  const PixelWindow window = settings.window.value_or(PixelWindow{0, 0, settings.width, settings.height});
  if (!window.fits(settings.width, settings.height))
    throw std::invalid_argument("render: the pixel window is empty or not inside the image");
  const ThinLensCamera camera(scene.camera(), settings.width, settings.height);
  const int width = window.width(), height = window.height();
  const IntegrateFn integrate = select_integrator(settings.integrator, scene.features());
  const IntegrateBatchFn integrate_batch = select_batch_integrator(settings.integrator, scene.features());
  const IntegratorSettings isettings{settings.max_depth, settings.rr_depth};
  const bool sample_lens = scene.features().lens;
  const bool sample_time = scene.features().motion;

  Film film(width, height);
  // Output layers only when asked: otherwise no film, and the integrator gets a null FirstHit.
  std::optional<LayerFilm> layer_film;
  // The denoiser is guided by albedo and normal, rendered for it when not asked for.
  const uint32_t film_outputs =
      settings.outputs | (settings.denoise ? uint32_t(kOutputAlbedo | kOutputNormal) : 0u);
  if (film_outputs)
    layer_film.emplace(width, height, film_outputs, camera.position(), camera.forward());
  // Path reuse among the pixels of reuse_block x reuse_block blocks (path_reuse.h).
  int reuse_block = std::clamp(settings.path_reuse, 1, RenderSettings::kMaxPathReuse);
  if (!settings.wavefront || settings.integrator != IntegratorKind::kPath ||
      !path_reuse_applies(scene, isettings))
    reuse_block = 1;
  const bool reuse = reuse_block > 1;
  const PixelOrder order =
      make_pixel_order(width, height, std::max(1, settings.tile_size), reuse_block);
  const int spp = std::max(1, settings.spp);
  // Per pixel: samples taken so far and the most it may take. Uniform sampling keeps every limit
  // at spp; adaptive sampling (render.noise_threshold) re-estimates the limits after each pass
  // from 16 samples on (renderer/adaptive_sampling.h). Sample indices stay consecutive per pixel
  // so each pixel's samples are a prefix of its Sobol sequence.
  std::vector<uint32_t> limit(size_t(width) * height, uint32_t(spp)), taken(size_t(width) * height, 0);
  const bool adaptive = settings.noise_threshold > 0.f;
  const AdaptiveLimits adaptive_limits{settings.noise_threshold, 16, spp};
  const PassPlan plan = plan_passes(settings, control, adaptive, adaptive_limits.min_samples);
  const uint32_t cmj_bits = sampler_cmj_bits(settings);

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
    // A time budget ends the render at its deadline whatever the samples say: the fraction is at
    // least the share of the budget spent, and the ETA at most what is left of it.
    if (settings.time_limit > 0) {
      const double share = std::min(1.0, p.elapsed_seconds / settings.time_limit);
      const double left = std::max(0.0, settings.time_limit - p.elapsed_seconds);
      p.fraction = std::max(p.fraction, share);
      p.eta_seconds = p.fraction > share ? std::min(p.eta_seconds, left) : left;
    }
    p.passes_done = passes_done;
    return p;
  };

  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  // Each render thread's wavefront scratch, made on its first work item and kept for the rest of
  // the render's items and passes: its batch's surface stages are built once per thread instead
  // of once per item (eight stage objects, each with its own copy of the scene's light and
  // coating tables, and some eighty lane arrays).
  tbb::enumerable_thread_specific<WavefrontScratch> scratch(camera, sample_lens, sample_time,
                                                            layer_film.has_value());
  int first_sample = 0;
  int passes_done = 0;
  double seconds_per_sample = 0.0;  // the last pass's, per sample per pixel
  for (int n = plan.next(0, 0.0); n > 0 && !stop.load();
       n = plan.next(first_sample, seconds_per_sample)) {
    const int s0 = first_sample, s1 = first_sample + n;
    const double pass_start = elapsed();
    // Limits are decided here, between passes, so the image does not depend on threads or tile
    // order; the progress total follows them so the fraction and ETA stay meaningful.
    const int threads = arena.max_concurrency();
    std::vector<size_t> items = order.tile_starts;
    if (adaptive && s0 >= adaptive_limits.min_samples) {
      arena.execute([&] { update_limits(film, adaptive_limits, &limit); });
      samples_total = 0;
      for (size_t i = 0; i < limit.size(); ++i) samples_total += std::max(limit[i], taken[i]);
      items = balanced_items(order, taken, limit, uint32_t(s1 - s0), 8 * threads);
    } else if (threads > 1 && items.size() - 1 < size_t(kItemsPerThread) * size_t(threads)) {
      items = balanced_items(order, taken, limit, uint32_t(s1 - s0), kItemsPerThread * threads);
    }
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, items.size() - 1, 1), [&](const auto& range) {
        const FlushDenormals flush_denormals;  // (core/flush_denormals.h: why)
        for (size_t item = range.begin(); item != range.end(); ++item) {
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
          PathCounters counters;
          FirstHit first_hit;
          FirstHit* const first = layer_film ? &first_hit : nullptr;
          uint64_t item_samples = 0, item_nonfinite = 0;
          // One camera sample of film pixel (fx, fy): the camera's dimensions of the pixel's
          // sampler, then its ray.
          auto camera_ray = [&](Sampler& sampler, int x, int y, uint32_t s) {
            sampler.start_pixel_sample(x, y, s);
            const CameraSample cs = take_camera_sample(sampler, sample_lens, sample_time);
            const CameraRay cr = camera.generate_ray(vec2(float(x), float(y)) + cs.film, cs.lens, cs.time);
            return Ray{cr.origin, cr.direction, cr.time};
          };
          // The item's samples in order: each pixel's next samples of this pass, up to its limit,
          // as a run [n0, n1) of sample indices per pixel.
          auto for_each_run = [&](auto&& take) {
            for (size_t k = items[item]; k < items[item + 1]; ++k) {
              const uint32_t pi = order.pixels[k];
              const uint32_t n0 = taken[pi], n1 = std::min(n0 + uint32_t(s1 - s0), limit[pi]);
              if (n0 >= n1) continue;
              taken[pi] = n1;
              take(pi, int(pi % uint32_t(width)), int(pi / uint32_t(width)), n0, n1);
            }
          };
          if (settings.wavefront) {
            // Batches of the item's samples in that order, one sampler per pixel of a batch;
            // the film takes each batch's results in that order, as the scalar loop adds them.
            const size_t capacity = std::min(kWavefrontBatch, (items[item + 1] - items[item]) * size_t(s1 - s0));
            WavefrontScratch& local = scratch.local();
            PathBatch& batch = local.batch;
            CameraStage& camera_stage = local.camera_stage;
            std::vector<Sampler>& samplers = local.samplers;
            std::vector<uint32_t>& batch_pixels = local.batch_pixels;
            std::vector<uint64_t>& batch_keys = local.batch_keys;
            batch.set_reuse(reuse);
            auto flush = [&] {
              camera_stage.generate(batch);
              integrate_batch(scene, isettings, batch, counters);
              if (reuse) {
                // The batch's paths grouped by (block, sample index), each group reused.
                std::vector<uint32_t>& grouped = local.grouped;
                std::vector<size_t>& starts = local.group_starts;
                grouped.resize(batch.size());
                std::iota(grouped.begin(), grouped.end(), 0u);
                std::stable_sort(grouped.begin(), grouped.end(),
                                 [&](uint32_t a, uint32_t b) { return batch_keys[a] < batch_keys[b]; });
                starts.clear();
                for (size_t i = 0; i < grouped.size(); ++i)
                  if (i == 0 || batch_keys[grouped[i]] != batch_keys[grouped[i - 1]]) starts.push_back(i);
                starts.push_back(grouped.size());
                counters.rays += reuse_paths(scene, batch.reuse_records(), batch.states(),
                                             grouped.data(), starts);
              }
              // Each run of one pixel's samples at once (the batch holds them consecutively).
              for (size_t i = 0; i < batch.size();) {
                const uint32_t pi = batch_pixels[i];
                size_t end = i + 1;
                while (end < batch.size() && batch_pixels[end] == pi) ++end;
                const int fx = int(pi % uint32_t(width)), fy = int(pi / uint32_t(width));
                item_nonfinite += film.add_samples(fx, fy, end - i, [&](size_t k) -> const Spectrum& {
                  return batch.radiance(i + k);
                });
                if (first)
                  for (size_t k = i; k < end; ++k) layer_film->add_sample(fx, fy, batch.first_hit(k));
                i = end;
              }
              item_samples += batch.size();
              batch.clear();
              samplers.clear();
              batch_pixels.clear();
              batch_keys.clear();
            };
            if (reuse) {
              // A block's pixels' runs interleaved in chunks, so each batch holds the block's
              // pixels at the same sample indices.
              struct Run { uint32_t pi; int fx, fy; uint32_t n0, n1; };
              std::vector<Run> runs;
              for_each_run([&](uint32_t pi, int fx, int fy, uint32_t n0, uint32_t n1) {
                runs.push_back(Run{pi, fx, fy, n0, n1});
              });
              // A block as make_pixel_order cuts it inside its tile, named by its first pixel.
              const int tile = std::max(1, settings.tile_size);
              auto block_of = [&](const Run& r) {
                const int bx = r.fx - (r.fx % tile) % reuse_block;
                const int by = r.fy - (r.fy % tile) % reuse_block;
                return uint64_t(by) * uint64_t(width) + uint64_t(bx);
              };
              for (size_t g0 = 0; g0 < runs.size();) {
                size_t g1 = g0 + 1;
                while (g1 < runs.size() && block_of(runs[g1]) == block_of(runs[g0])) ++g1;
                const uint64_t block = block_of(runs[g0]);
                const uint32_t members = uint32_t(g1 - g0);
                const uint32_t chunk = std::max<uint32_t>(1, uint32_t(capacity) / members);
                uint32_t longest = 0;
                for (size_t r = g0; r < g1; ++r) longest = std::max(longest, runs[r].n1 - runs[r].n0);
                for (uint32_t off = 0; off < longest; off += chunk) {
                  size_t need = 0;
                  for (size_t r = g0; r < g1; ++r)
                    if (runs[r].n0 + off < runs[r].n1)
                      need += std::min(chunk, runs[r].n1 - runs[r].n0 - off);
                  if (batch_pixels.size() + need > capacity) flush();
                  for (size_t r = g0; r < g1; ++r) {
                    const Run& run = runs[r];
                    if (run.n0 + off >= run.n1) continue;
                    const uint32_t s = run.n0 + off, count = std::min(chunk, run.n1 - s);
                    const int x = window.x0 + run.fx, y = window.y0 + run.fy;
                    samplers.emplace_back(settings.seed, cmj_bits);
                    samplers.back().start_pixel_sample(x, y, s);
                    camera_stage.add_run(&samplers.back(), x, y, s, count);
                    batch_pixels.insert(batch_pixels.end(), count, run.pi);
                    for (uint32_t j = 0; j < count; ++j) batch_keys.push_back((block << 32) | (s + j));
                  }
                }
                g0 = g1;
              }
            } else {
              // A pixel's run of samples queued at once, up to the batch's end (a call and two
              // push_backs per sample were 3% of the furnace's profile).
              for_each_run([&](uint32_t pi, int fx, int fy, uint32_t n0, uint32_t n1) {
                const int x = window.x0 + fx, y = window.y0 + fy;
                for (uint32_t s = n0; s < n1;) {
                  if (batch_pixels.size() >= capacity) flush();
                  const uint32_t run = uint32_t(std::min<size_t>(n1 - s, capacity - batch_pixels.size()));
                  if (samplers.empty() || batch_pixels.back() != pi) {
                    samplers.emplace_back(settings.seed, cmj_bits);
                    samplers.back().start_pixel_sample(x, y, s);
                  }
                  camera_stage.add_run(&samplers.back(), x, y, s, run);
                  batch_pixels.insert(batch_pixels.end(), run, pi);
                  s += run;
                }
              });
            }
            if (!batch_pixels.empty()) flush();
          } else {
            Sampler sampler(settings.seed, cmj_bits);
            for_each_run([&](uint32_t, int fx, int fy, uint32_t n0, uint32_t n1) {
              for (uint32_t s = n0; s < n1; ++s) {
                const Ray ray = camera_ray(sampler, window.x0 + fx, window.y0 + fy, s);
                const Spectrum L = integrate(scene, isettings, ray, sampler, counters, first);
                if (!film.add_sample(fx, fy, L)) ++item_nonfinite;
                if (first) layer_film->add_sample(fx, fy, first_hit);
                ++item_samples;
              }
            });
          }
          rays += counters.rays;
          samples_done += item_samples;
          if (item_nonfinite) nonfinite += item_nonfinite;
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
    seconds_per_sample = (elapsed() - pass_start) / double(n);
    if (control.on_pass) control.on_pass(film.resolve(), make_progress(passes_done));
  }

  RenderResult result;
  result.window = window;
  result.image = film.resolve();
  result.variance = film.resolve_variance();
  if (layer_film) result.layers = layer_film->resolve();
  RenderStats& st = result.stats;
  if (settings.denoise && !cancelled.load()) denoise_result(settings.outputs, &result);
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
