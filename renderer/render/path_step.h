#pragma once
// One bounce of a path, shared by the two drivers of the integrators: the scalar one
// (integrator.cpp, one path from camera to end, one ray at a time: the readable reference) and
// the wavefront one (wavefront_integrator.cpp, many paths a bounce at a time, rays traced in
// packets). A path's state between bounces is a PathState; the visibility test of its
// next-event estimate is handed back as a ShadowQuery for the driver to trace, so a driver can
// batch them. Both drivers run exactly these steps in this order, so they give the same image.
#include <array>
#include <climits>
#include <cstdint>
#include <optional>
#include <utility>

#include "renderer/core/frame.h"
#include "renderer/core/ray.h"
#include "renderer/lights/area_light.h"
#include "renderer/materials/surface_bsdf.h"
#include "renderer/render/output_layers.h"
#include "renderer/sampling/sampler.h"
#include "renderer/sampling/sampling.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

struct IntegratorSettings {
  int max_depth = 8;  // path segments, Mitsuba 3 convention; <0 = unlimited
  int rr_depth = 5;
};

struct PathCounters {
  uint64_t rays = 0;
};

// Feature bits an instantiation is compiled for. A bit that is off removes that code from the
// loop entirely (Cycles compiles only the kernel features a scene uses); a bit that is on keeps
// the run-time test, so the all-on instantiation is the generic integrator and any
// instantiation gives bit-identical images on the scenes it is chosen for.
enum IntegratorFeature : uint32_t {
  kFeatureAbsorption = 1u << 0,    // Beer-Lambert attenuation inside dielectrics
  kFeatureTransmission = 1u << 1,  // refraction: eta bookkeeping for Russian roulette
  kFeatureEnvironment = 1u << 2,   // escaping rays gather the environment
  kFeatureLights = 1u << 3,        // next-event estimation (any light at all)
  kFeatureAll = (1u << 4) - 1,
};

// A driver's instantiations, one per integrator kind and feature mask, and the choice among
// them: Kernel<kDistributed, kFeatures>::fn is the driver's function of that instantiation (a
// class template, since a function template cannot be passed as a template argument).
template <typename Fn, template <bool, uint32_t> class Kernel>
class FeatureInstantiations {
 public:
  static Fn select(IntegratorKind kind, uint32_t mask) {
    return kind == IntegratorKind::kDistributed ? kDistributed[mask] : kPath[mask];
  }

 private:
  template <bool kDistributedKind, size_t... kMasks>
  static constexpr std::array<Fn, sizeof...(kMasks)> table(std::index_sequence<kMasks...>) {
    return {Kernel<kDistributedKind, uint32_t(kMasks)>::fn...};
  }
  static constexpr auto kPath = table<false>(std::make_index_sequence<kFeatureAll + 1>{});
  static constexpr auto kDistributed = table<true>(std::make_index_sequence<kFeatureAll + 1>{});
};

// What a path carries from one bounce to the next.
struct PathState {
  Ray ray;                  // the segment to trace next
  Spectrum radiance{0.f};   // gathered so far
  Spectrum beta{1.f};       // throughput
  // The strategy that produced `ray`, for MIS on the emitter it may hit.
  float prev_pdf = 0.f;
  bool prev_delta = true;
  vec3 prev_p{0.f};
  float eta = 1.f;  // product of relative iors crossed (Russian roulette)
  int depth = 1;    // segment number of `ray`, from 1 for the camera ray
  // The geometric normal at prev_p (0 at the camera), where a light tree weighed the lights
  // for the MIS weight of the emitter `ray` may hit.
  vec3 prev_n{0.f};

  explicit PathState(const Ray& camera_ray) : ray(camera_ray), prev_p(camera_ray.origin) {}
  PathState() = default;
};

// A next-event estimate waiting for its visibility test: `contribution` counts if nothing lies
// on `ray` before ray.t_max.
struct ShadowQuery {
  Ray ray;
  Spectrum contribution{0.f};
};

namespace path_step_detail {

// A direction pair is usable only if the shading frame and the true surface agree on whether it
// reflects or transmits; otherwise shading normals would leak light through surfaces
// (Veach 1997 section 5.3).
[[gnu::always_inline]] inline bool geometry_agrees(const vec3& wi_world, const vec3& wo_world, const vec3& ng,
                            const vec3& wi_local, const vec3& wo_local) {
  const float geo = glm::dot(wi_world, ng) * glm::dot(wo_world, ng);
  const float shade = wi_local.z * wo_local.z;
  return geo != 0.f && (geo > 0.f) == (shade > 0.f);
}

// The shading frame with its tangent along dp/du, which a normal map's x axis follows
// (Mitsuba 3's SurfaceInteraction::initialize_sh_frame: Gram-Schmidt of dp/du against the
// shading normal). Any frame of the normal where the parametrisation degenerates.
inline Frame tangent_frame(const Scene& scene, float time, SurfaceHit* hit) {
  scene.surface_derivatives(time, hit);
  const vec3 n = hit->ns;
  const vec3 s = hit->dpdu - n * glm::dot(n, hit->dpdu);
  const float len = glm::length(s);
  if (!(len > 0.f) || !std::isfinite(len)) return Frame(n);
  Frame f;
  f.n = n;
  f.s = s / len;
  f.t = glm::cross(n, f.s);
  return f;
}

// The output layers' view of the camera ray's first hit (docs/output-layers.md). Out of line and
// only called when layers are requested: it repeats the texture lookup and tangent frame the
// loop builds later (after emission and the depth test), which costs a requested layer a little
// and the beauty render nothing.
[[gnu::noinline]] inline void record_first_hit(const Scene& scene, const Material& material,
                                               const Ray& ray, SurfaceHit hit, FirstHit* first) {
  std::optional<SurfaceBsdf> textured;
  const SurfaceBsdf* bsdf = &material.bsdf();
  if (material.varies()) bsdf = &textured.emplace(material.bsdf_at(TextureQuery{hit.p, hit.uv, ray.time}));
  // The normal the BSDF shades with: the hit's, or a normal map's within the tangent frame.
  const Frame frame = material.normal_mapped() ? tangent_frame(scene, ray.time, &hit) : Frame(hit.ns);
  vec3 n = frame.to_world(bsdf->shading_normal(frame.to_local(-ray.direction)));
  // Facing the viewer, as Cycles' Normal and denoising normal passes: the side the camera sees.
  if (glm::dot(n, ray.direction) > 0.f) n = -n;
  first->hit = true;
  first->albedo = bsdf->albedo();
  first->normal = n;
  first->p = hit.p;
}

inline void record_miss(const EnvironmentLight* environment, const Ray& ray, FirstHit* first) {
  first->hit = false;
  first->normal = vec3(0.f);
  // The background's colour, clamped into an albedo's range: a denoiser then keeps the
  // environment's detail where the camera sees it directly (docs/output-layers.md).
  first->albedo = environment ? glm::clamp(environment->radiance(ray.direction), Spectrum(0.f),
                                           Spectrum(1.f))
                              : Spectrum(0.f);
  if (!is_finite(first->albedo)) first->albedo = Spectrum(0.f);
}

}  // namespace path_step_detail

// The lights an integrator's next-event estimation chooses from: every light for the
// distributed integrator (its diffuse lobes see direct light through light sampling alone), for
// the path integrator all but those BSDF sampling covers better (Scene::mis_light_sampler).
template <bool kDistributed>
[[gnu::always_inline]] inline const LightSampler& next_event_lights(const Scene& scene) {
  if constexpr (kDistributed) return scene.light_sampler();
  else return scene.mis_light_sampler();
}

// The light `index` as that integrator samples it, and the environment whose density weighs an
// escaped path's MIS: the path integrator's environment map is sampled where it is brighter than
// its mean (Scene::mis_light, MIS compensation), the distributed integrator's everywhere.
template <bool kDistributed>
[[gnu::always_inline]] inline const Light& next_event_light(const Scene& scene, int index) {
  if constexpr (kDistributed) return scene.light(index);
  else return scene.mis_light(index);
}
template <bool kDistributed>
[[gnu::always_inline]] inline const EnvironmentLight* escape_environment(const Scene& scene) {
  if constexpr (kDistributed) return scene.environment();
  else return scene.mis_environment();
}

// What an escaped path gathers from the environment's answer for its ray: `radiance`, and
// `pdf` (asked for only when the last bounce was not a delta) for the MIS weight.
template <bool kDistributed>
[[gnu::always_inline]] inline void path_gather_environment(const Scene& scene, PathState& s,
                                                           const Spectrum& radiance, float pdf) {
  const LightSampler& lights = next_event_lights<kDistributed>(scene);
  const float w =
      s.prev_delta ? 1.f : power_heuristic(s.prev_pdf, lights.pmf(scene.environment_light()) * pdf);
  s.radiance += s.beta * radiance * w;
}

// The output layers' record of a camera ray that escaped: path_escaped's first part (a driver
// that asks the environment for many paths at once takes it one path at a time).
inline void path_escape_record(const Scene& scene, const PathState& s, FirstHit* first) {
  if (first && s.depth == 1) path_step_detail::record_miss(scene.environment(), s.ray, first);
}

// The path's ray escaped the scene: the environment's radiance, weighted by MIS against light
// sampling (weight 1 where the integrator leaves the environment to BSDF sampling: its pmf is
// 0). The path ends.
template <bool kDistributed, uint32_t kFeatures>
inline void path_escaped(const Scene& scene, PathState& s, FirstHit* first) {
  const EnvironmentLight* environment = escape_environment<kDistributed>(scene);
  path_escape_record(scene, s, first);
  if constexpr ((kFeatures & kFeatureEnvironment) != 0) {
    if (!environment) return;
    float pdf = 0.f;
    const Spectrum radiance = environment->radiance_and_pdf(s.ray.direction, s.prev_delta ? nullptr : &pdf);
    path_gather_environment<kDistributed>(scene, s, radiance, pdf);
  }
}

// The path's ray hit `hit`, first part: the first-hit record, Beer-Lambert absorption and the
// emission it sees. False if the path ends here (it reached max_depth); else path_scatter goes
// on from the same hit.
template <bool kDistributed, uint32_t kFeatures>
[[gnu::always_inline]] inline bool path_arrive(const Scene& scene, const IntegratorSettings& settings,
                                               PathState& s, const SurfaceHit& hit,
                                               FirstHit* first) {
  using namespace path_step_detail;
  const int max_depth = settings.max_depth < 0 ? INT_MAX : settings.max_depth;
  const LightSampler& lights = next_event_lights<kDistributed>(scene);
  const Ray& ray = s.ray;
  const SceneObject& obj = scene.object(hit.object);
  const Material& material = scene.material(obj.material);
  const bool front = glm::dot(ray.direction, hit.ng) < 0.f;
  if (first && s.depth == 1) record_first_hit(scene, material, ray, hit, first);

  // Beer-Lambert: a segment that ends on the back of an absorbing dielectric ran inside it.
  if constexpr ((kFeatures & kFeatureAbsorption) != 0) {
    if (scene.features().absorption && !front) {
      const Spectrum sigma = material.absorption();
      if (!is_black(sigma)) s.beta *= glm::exp(-sigma * hit.t);
    }
  }
  if (obj.area_light && front) {
    float w = 1.f;
    if (!s.prev_delta)
      w = power_heuristic(s.prev_pdf, lights.pmf(obj.light, s.prev_p, s.prev_n) *
                                          obj.area_light->pdf(s.prev_p, hit.p, hit.ng, ray.time));
    s.radiance += s.beta * obj.area_light->radiance(TextureQuery{hit.p, hit.uv, ray.time}) * w;
  }
  return s.depth < max_depth;
}

// Second part, after path_arrive: next-event estimation (its visibility test returned in
// *shadow when `*has_shadow`), then the BSDF's sample for the next segment and Russian
// roulette. Returns whether the path goes on with s.ray.
// `sampler`: a Sampler, or anything with its get_1d/get_2d/get_1d_2d (the wavefront driver's
// PrefetchedSampler hands out values computed for a whole bounce at once).
template <bool kDistributed, uint32_t kFeatures, class PathSampler>
inline bool path_scatter(const Scene& scene, const IntegratorSettings& settings, PathState& s,
                         SurfaceHit& hit, PathSampler& sampler, PathCounters& counters,
                         ShadowQuery* shadow, bool* has_shadow) {
  using namespace path_step_detail;
  *has_shadow = false;
  const LightSampler& lights = next_event_lights<kDistributed>(scene);
  constexpr uint32_t kContinueLobes = kDistributed ? uint32_t(kLobeNonDiffuse) : uint32_t(kLobeAll);
  const Ray& ray = s.ray;
  const Material& material = scene.material(scene.object(hit.object).material);

  // The BSDF here: the material's own where nothing varies over its surface (no lookup, the
  // path untextured scenes take), else the one with its textures looked up at this point.
  std::optional<SurfaceBsdf> textured;
  const SurfaceBsdf* bsdf = &material.bsdf();
  if (material.varies()) bsdf = &textured.emplace(material.bsdf_at(TextureQuery{hit.p, hit.uv, ray.time}));
  const Frame frame = material.normal_mapped() ? tangent_frame(scene, ray.time, &hit) : Frame(hit.ns);
  const vec3 wi_world = -ray.direction;
  const vec3 wi = frame.to_local(wi_world);
  const uint32_t lobes = bsdf->lobes();

  // Next-event estimation.
  if ((kFeatures & kFeatureLights) != 0 && (lobes & ~uint32_t(kLobeDelta)) && !lights.empty()) {
    float u_light;
    vec2 u_point;
    sampler.get_1d_2d(&u_light, &u_point);  // one 3D point (Sampler::get_1d_2d)
    LightSample ls;
    float light_pmf;
    const int light = lights.choose(u_light, hit.p, hit.ng, &light_pmf);
    if (light >= 0 && next_event_light<kDistributed>(scene, light).sample(hit.p, ray.time, u_point, &ls)) {
      ls.pdf *= light_pmf;
      const vec3 wo = frame.to_local(ls.wi);
      if (geometry_agrees(wi_world, ls.wi, hit.ng, wi, wo)) {
        // The BSDF's value and, for MIS against its own sampling, its pdf, from one call that
        // computes their shared terms once (a delta light needs no pdf).
        const auto eval_mis = [&](const BsdfContext& ctx) {
          if (ls.is_delta) return bsdf->eval(ctx, wi, wo);
          const BsdfEvalPdf e = bsdf->eval_pdf(ctx, wi, wo);
          return e.f * power_heuristic(ls.pdf, e.pdf);
        };
        Spectrum f;
        if constexpr (kDistributed) {
          // Diffuse lobes see direct light through light sampling alone; the other lobes
          // share it with their own sampling by MIS.
          const BsdfContext diffuse{kLobeDiffuse}, rest{kLobeNonDiffuse};
          f = bsdf->eval(diffuse, wi, wo) + eval_mis(rest);
        } else {
          f = eval_mis(BsdfContext{});
        }
        if (!is_black(f)) {
          const vec3 origin = offset_ray_origin(hit.p, hit.p_error, hit.ng, ls.wi);
          vec3 dir = ls.wi;
          float t_max = kInfinity;
          if (std::isfinite(ls.distance)) {
            const vec3 target = ls.n == vec3(0.f)
                                    ? ls.p
                                    : offset_ray_origin(ls.p, ls.p_error, ls.n, -ls.wi);
            const vec3 d = target - origin;
            const float dist = glm::length(d);
            dir = dist > 0.f ? d / dist : ls.wi;
            // A point light is a point in free space: nothing at the far end to miss, and a
            // relative shortening would let the ray stop short of a wall the light sits
            // closer to than 1e-4 of the distance (a leak the stress suite checks). An area
            // light's point is offset off its surface already; the epsilon absorbs rounding.
            t_max = ls.n == vec3(0.f) ? dist : dist * (1.f - kShadowEpsilon);
          }
          ++counters.rays;
          if (t_max > 0.f) {
            shadow->ray = Ray{origin, dir, ray.time, t_max};
            shadow->contribution = s.beta * f * ls.value / ls.pdf;
            *has_shadow = true;
          }
        }
      }
    }
  }

  if constexpr (kDistributed) {
    if (!(lobes & kLobeNonDiffuse)) return false;
  }
  float u_lobe;
  vec2 u_dir;
  sampler.get_1d_2d(&u_lobe, &u_dir);  // one 3D point (Sampler::get_1d_2d)
  const auto bs = bsdf->sample(BsdfContext{kContinueLobes}, wi, u_lobe, u_dir);
  if (!bs) return false;
  const vec3 wo_world = frame.to_world(bs->wo);
  if (!geometry_agrees(wi_world, wo_world, hit.ng, wi, bs->wo)) return false;
  s.beta *= bs->weight;
  s.prev_pdf = bs->pdf;
  s.prev_delta = (bs->lobe & kLobeDelta) != 0;
  s.prev_p = hit.p;
  s.prev_n = hit.ng;
  if constexpr ((kFeatures & kFeatureTransmission) != 0) s.eta *= bs->eta;
  s.ray = Ray{offset_ray_origin(hit.p, hit.p_error, hit.ng, wo_world), wo_world, ray.time};

  const float beta_max = max_component(s.beta);
  if (!(beta_max > 0.f)) return false;
  // Russian roulette as Mitsuba 3: survival by throughput, with eta^2 undoing the radiance
  // scaling of refraction so paths inside glass are not killed early.
  if (s.depth >= settings.rr_depth) {
    const float q = std::min(beta_max * s.eta * s.eta, 0.95f);
    if (sampler.get_1d() >= q) return false;
    s.beta /= q;
  }
  ++s.depth;
  return true;
}

// A whole step at a hit: path_arrive, then path_scatter.
template <bool kDistributed, uint32_t kFeatures, class PathSampler>
inline bool path_hit(const Scene& scene, const IntegratorSettings& settings, PathState& s,
                     SurfaceHit& hit, PathSampler& sampler, PathCounters& counters,
                     FirstHit* first, ShadowQuery* shadow, bool* has_shadow) {
  *has_shadow = false;
  if (!path_arrive<kDistributed, kFeatures>(scene, settings, s, hit, first)) return false;
  return path_scatter<kDistributed, kFeatures>(scene, settings, s, hit, sampler, counters,
                                               shadow, has_shadow);
}

}  // namespace penumbra
