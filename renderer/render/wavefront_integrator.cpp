#include "renderer/render/wavefront_integrator.h"

#include <algorithm>
#include <array>
#include <numeric>

#include "renderer/render/integrator.h"

namespace penumbra {

PathBatch::PathBatch(size_t capacity, bool record_first_hits)
    : capacity_(std::max<size_t>(1, capacity)), record_first_hits_(record_first_hits) {
  size_arrays();
}

void PathBatch::grow() {
  capacity_ *= 2;
  size_arrays();
}

// Every per-path and per-slot array to the capacity.
void PathBatch::size_arrays() {
  states_.resize(capacity_);
  samplers_.resize(capacity_);
  cursors_.resize(capacity_);
  if (record_first_hits_) firsts_.resize(capacity_);
  if (reuse_on_) reuse_.resize(capacity_);
  live_.reserve(capacity_);
  hits_.resize(capacity_);
  found_.resize(capacity_);
  shadows_.resize(capacity_);
  shadow_paths_.resize(capacity_);
  shadow_slots_.resize(capacity_);
  hit_slots_.resize(capacity_);
  miss_slots_.resize(capacity_);
}

// The stages of the models `scene`'s surfaces use, and which object goes to which.
void make_stages(const Scene& scene, PathBatch& b) {
  b.stages_.clear();
  b.stage_of_.assign(scene.object_count(), -1);
  b.lobe_choices_ = false;
  b.roulette_at_lobe_ = false;
  for (StageModel model : kStageModels) {
    auto stage = std::make_unique<SurfaceStage>(scene, model);
    bool used = false;
    for (uint32_t o = 0; o < scene.object_count(); ++o) {
      if (!stage->takes(o)) continue;
      b.stage_of_[o] = int8_t(b.stages_.size());
      used = true;
    }
    if (used) {
      b.lobe_choices_ = b.lobe_choices_ || stage->needs_lobe_choice();
      b.roulette_at_lobe_ = b.roulette_at_lobe_ || stage->roulette_at_lobe_dimension();
      b.stages_.push_back(std::move(stage));
    }
  }
  b.queues_.resize(b.stages_.size());
  for (PathBatch::StageQueue& q : b.queues_) q.reserve(b.capacity_);
  // Surfaces no stage takes step through path_scatter, which may pick a lobe.
  // (Their Dirac surfaces read the roulette value where the lobe pair starts: through
  // PrefetchedSampler, which has it from the sampler when it was not computed, at a cost.)
  for (uint32_t o = 0; o < scene.object_count(); ++o) {
    b.lobe_choices_ = b.lobe_choices_ || b.stage_of_[o] < 0;
    b.roulette_at_lobe_ = b.roulette_at_lobe_ || b.stage_of_[o] < 0;
  }
  b.staged_scene_ = &scene;
}

// The paths a surface stage takes at once: its some 60 lane arrays of 128 floats fit the
// first-level cache with the hits and states they are read from (chunks of 64 and 256 measured
// the same, the whole bounce's paths at once 2-6% slower: docs/performance.md, session 35).
constexpr size_t kStageChunk = 128;

template <bool kDistributed, uint32_t kFeatures>
void integrate_batch(const Scene& scene, const IntegratorSettings& settings, PathBatch& b,
                     PathCounters& counters) {
  using StageQueue = PathBatch::StageQueue;
  constexpr int kPacket = Scene::kPacketSize;
  std::vector<uint32_t>& live = b.live_;
  live.resize(b.size());
  std::iota(live.begin(), live.end(), 0u);
  const bool reuse = !kDistributed && b.reuse_on_;
  if (reuse)
    for (size_t p = 0; p < b.size(); ++p) {
      b.reuse_[p].has_x1 = false;
      b.reuse_[p].has_x2 = false;
    }
  int bounce = 0;
  for (bool camera_rays = true; !live.empty(); camera_rays = false, ++bounce) {
    // Trace: the live paths' rays, in packets of consecutive live paths.
    std::array<Ray, kPacket> rays;
    std::array<bool, kPacket> found;
    for (size_t k = 0; k < live.size(); k += kPacket) {
      const int count = int(std::min<size_t>(kPacket, live.size() - k));
      for (int i = 0; i < count; ++i) rays[i] = b.states_[live[k + i]].ray;
      scene.intersect_packet(rays.data(), count, camera_rays, &b.hits_[k], found.data());
      for (int i = 0; i < count; ++i) b.found_[k + i] = found[i];
    }
    counters.rays += live.size();
    // The slots whose ray hit something, in order (hit j is slot hit_slots[j]), and those whose
    // ray escaped: written whatever the flag, the place advanced by it (whether a ray hits is
    // random, and branches on it mispredicted in every loop that tested it).
    std::vector<uint32_t>& hit_slots = b.hit_slots_;
    std::vector<uint32_t>& miss_slots = b.miss_slots_;
    size_t hit_count = 0, miss_count = 0;
    for (size_t k = 0; k < live.size(); ++k) {
      hit_slots[hit_count] = uint32_t(k);
      miss_slots[miss_count] = uint32_t(k);
      hit_count += b.found_[k];
      miss_count += 1 - b.found_[k];
    }
    // Path reuse records the camera rays' hits and the second ones with the throughput they
    // arrive with (path_reuse.h).
    if (reuse && bounce < 2) {
      for (size_t j = 0; j < hit_count; ++j) {
        const size_t k = hit_slots[j];
        const uint32_t p = live[k];
        ReuseRecord& r = b.reuse_[p];
        if (bounce == 0) {
          r.x1 = b.hits_[k];
          r.wi1 = -b.states_[p].ray.direction;
          r.time = b.states_[p].ray.time;
          r.has_x1 = true;
        } else {
          r.x2 = b.hits_[k];
          r.beta1 = b.states_[p].beta;
          r.has_x2 = true;
        }
      }
    }

    // The sampler values the paths that hit something will take, for all of them at once (no
    // light choice and light point where the integrator samples no light).
    const bool next_event =
        (kFeatures & kFeatureLights) != 0 && !next_event_lights<kDistributed>(scene).empty();
    BounceSamples& samples = b.samples_;
    // The 1D values of the get_1d_2d pairs (Sampler::get_1d_2d) only where someone reads them:
    // a light choice among several lights, a lobe choice where a surface has one (a path that
    // takes a pair not computed here gets it from its sampler, PrefetchedSampler; the stages
    // read the values only where their step uses them).
    constexpr bool kStages = !kDistributed;
    if (kStages && b.staged_scene_ != &scene) make_stages(scene, b);
    const bool lobe_pairs = !kStages || b.lobe_choices_;
    // Whether a path of this bounce plays Russian roulette (a batch's paths move in step, so
    // at every depth all or none).
    bool roulette = false;
    for (size_t j = 0; j < hit_count; ++j)
      roulette |= b.states_[live[hit_slots[j]]].depth >= settings.rr_depth;
    if (next_event) {
      // Dimensions 0 and 1 are also the lobe and direction of a surface whose lobes are all
      // Dirac (it estimates no light: a smooth dielectric picks reflection or refraction there).
      const LightSampler& lights = next_event_lights<kDistributed>(scene);
      const bool light_pairs = lights.cdf().size() > 1 || lights.spatial();
      // The stages read the pairs' first dimensions only as the pairs' 1D values, but for the
      // roulette of Dirac surfaces at the lobe's (SurfaceStage::add_many), and the roulette
      // value (dimension 4, or 2 at Dirac surfaces) only at a depth that plays it.
      const uint32_t unread_x =
          !kStages ? 0u : 0b00001u | (!roulette ? 0b10100u : b.roulette_at_lobe_ ? 0u : 0b00100u);
      samples.start(hit_count, BounceSamples::kBounce, BounceSamples::kBouncePairs,
                    (light_pairs || lobe_pairs ? 0b00001u : 0u) | (lobe_pairs ? 0b00100u : 0u),
                    BounceSamples::kBounceTwoD, unread_x);
    } else {
      samples.start(hit_count, BounceSamples::kBounceWithoutLight,
                    BounceSamples::kBounceWithoutLightPairs, lobe_pairs ? 0b001u : 0u,
                    BounceSamples::kBounceWithoutLightTwoD,
                    !kStages ? 0u : roulette ? 0b001u : 0b101u);
    }
    for (size_t j = 0; j < hit_count; ++j) {
      const uint32_t p = live[hit_slots[j]];
      samples.add(*b.samplers_[p], b.cursors_[p]);
    }
    samples.compute();

    // Shade: every live path takes its step. Paths on plain Lambertian surfaces, rough
    // conductors and plastics (path integrator) take theirs in the surface stages, the others one by one;
    // each path's results go to its own slot k, and the survivors and shadow queries are then
    // gathered in path order, as the scalar loop would leave them.
    if (kStages)
      for (StageQueue& q : b.queues_) q.clear();
    std::vector<uint8_t>& goes_on = b.goes_on_;
    std::vector<uint8_t>& has_shadow = b.has_shadow_;
    goes_on.assign(live.size(), 0);
    has_shadow.assign(live.size(), 0);
    std::vector<uint32_t>& hit_of = b.hit_of_;
    hit_of.resize(live.size());
    const EnvironmentLight* environment = escape_environment<kDistributed>(scene);
    const bool escapes_together = environment && environment->prefers_many();
    b.escaped_.clear();
    for (size_t m = 0; m < miss_count; ++m) {
      const uint32_t p = live[miss_slots[m]];
      PathState& s = b.states_[p];
      FirstHit* first = b.record_first_hits_ ? &b.firsts_[p] : nullptr;
      if ((kFeatures & kFeatureEnvironment) != 0 && escapes_together) {
        // path_escaped for all of them at once below, where the environment answers together.
        path_escape_record(scene, s, first);
        b.escaped_.push_back(p);
      } else {
        path_escaped<kDistributed, kFeatures>(scene, s, first);
      }
    }
    for (size_t j = 0; j < hit_count; ++j) {
      const size_t k = hit_slots[j];
      const uint32_t p = live[k];
      PathState& s = b.states_[p];
      FirstHit* first = b.record_first_hits_ ? &b.firsts_[p] : nullptr;
      hit_of[k] = uint32_t(j);
      SurfaceHit& hit = b.hits_[k];
      const int stage = kStages ? b.stage_of_[hit.object] : -1;
      if (stage >= 0) {
        // Queued for the stage, which takes its paths' states and hits together below.
        if (path_arrive<kDistributed, kFeatures>(scene, settings, s, hit, first)) {
          b.queues_[size_t(stage)].push_back(uint32_t(k));
        }
        continue;
      }
      PrefetchedSampler sampler(*b.samplers_[p], b.cursors_[p], samples, j);
      bool shadow;
      goes_on[k] = path_hit<kDistributed, kFeatures>(scene, settings, s, hit, sampler, counters,
                                                     first, &b.shadows_[k], &shadow);
      has_shadow[k] = shadow;
      b.cursors_[p] = sampler.cursor();
    }
    if (const size_t n = b.escaped_.size()) {
      b.escaped_dirs_.resize(n);
      b.escaped_want_pdf_.resize(n);
      b.escaped_radiance_.resize(n);
      b.escaped_pdf_.assign(n, 0.f);
      for (size_t e = 0; e < n; ++e) {
        const PathState& s = b.states_[b.escaped_[e]];
        b.escaped_dirs_[e] = s.ray.direction;
        b.escaped_want_pdf_[e] = !s.prev_delta;
      }
      environment->radiance_and_pdf_many(n, b.escaped_dirs_.data(), b.escaped_want_pdf_.data(),
                                         b.escaped_radiance_.data(), b.escaped_pdf_.data());
      for (size_t e = 0; e < n; ++e)
        path_gather_environment<kDistributed>(scene, b.states_[b.escaped_[e]], b.escaped_radiance_[e],
                                              b.escaped_pdf_[e]);
    }
    // Each stage takes its paths in chunks whose lane arrays stay in the first-level cache from
    // add_many through compute to deliver.
    for (size_t g = 0; kStages && g < b.stages_.size(); ++g) {
      SurfaceStage& stage = *b.stages_[g];
      const StageQueue& q = b.queues_[g];
      for (size_t c = 0; c < q.size(); c += kStageChunk) {
        const size_t m = std::min(kStageChunk, q.size() - c);
        stage.start(m);
        stage.add_many(m, q.data() + c, live.data(), hit_of.data(), b.states_.data(),
                       b.hits_.data(), samples.x(0), samples.y(0), samples.z(0),
                       samples.stride(), next_event);
        stage.compute(settings, next_event);
        std::vector<uint32_t>& unstaged = b.unstaged_;
        unstaged.clear();
        counters.rays += stage.deliver(live.data(), b.states_.data(), b.cursors_.data(),
                                       goes_on.data(), has_shadow.data(), b.shadows_.data(),
                                       &unstaged);
        // Lanes whose parameters leave the model: the step one path at a time.
        for (const uint32_t lane : unstaged) {
          const size_t k = stage.slot(lane);
          const uint32_t p = live[k];
          PrefetchedSampler sampler(*b.samplers_[p], b.cursors_[p], samples, hit_of[k]);
          bool shadow;
          goes_on[k] = path_scatter<kDistributed, kFeatures>(scene, settings, b.states_[p],
                                                             b.hits_[k], sampler, counters,
                                                             &b.shadows_[k], &shadow);
          has_shadow[k] = shadow;
          b.cursors_[p] = sampler.cursor();
        }
      }
    }
    // The radiance with the second hits' emission and before their next-event estimates.
    if (reuse && bounce == 1)
      for (size_t j = 0; j < hit_count; ++j) {
        const uint32_t p = live[hit_slots[j]];
        b.reuse_[p].radiance_at_x2 = b.states_[p].radiance;
      }
    // The shadow queries stay in their slots (copying 44-byte queries into a compact array
    // stalled on store forwarding); their slots and paths are listed in path order. Written
    // whatever the flags, the next entry's place advanced by them: the flags are random and
    // branches on them mispredicted.
    size_t survivors = 0, shadows = 0;
    for (size_t k = 0; k < live.size(); ++k) {
      const uint32_t p = live[k];
      b.shadow_slots_[shadows] = uint32_t(k);
      b.shadow_paths_[shadows] = p;
      shadows += has_shadow[k];
      live[survivors] = p;  // survivors <= k: reads stay ahead of writes
      survivors += goes_on[k];
    }
    live.resize(survivors);

    // The bounce's shadow rays; an unblocked one adds its estimate before the path's next step,
    // as in the scalar driver.
    std::array<bool, kPacket> blocked;
    for (size_t k = 0; k < shadows; k += kPacket) {
      const int count = int(std::min<size_t>(kPacket, shadows - k));
      for (int i = 0; i < count; ++i) rays[i] = b.shadows_[b.shadow_slots_[k + i]].ray;
      scene.occluded_packet(rays.data(), count, blocked.data());
      for (int i = 0; i < count; ++i)
        if (!blocked[i])
          b.states_[b.shadow_paths_[k + i]].radiance += b.shadows_[b.shadow_slots_[k + i]].contribution;
    }
  }
}

namespace {

template <bool kDistributed, uint32_t kFeatures>
struct BatchKernel {
  static constexpr IntegrateBatchFn fn = &integrate_batch<kDistributed, kFeatures>;
};
using BatchInstantiations = FeatureInstantiations<IntegrateBatchFn, BatchKernel>;

}  // namespace

IntegrateBatchFn select_batch_integrator(IntegratorKind kind, const SceneFeatures& features) {
  return BatchInstantiations::select(kind, integrator_feature_mask(features, kind));
}

IntegrateBatchFn select_generic_batch_integrator(IntegratorKind kind) {
  return BatchInstantiations::select(kind, kFeatureAll);
}

}  // namespace penumbra
