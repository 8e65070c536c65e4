#include "renderer/render/integrator.h"

#include "renderer/render/path_step.h"

namespace penumbra {
namespace {

// The scalar driver: one path from the camera to its end, one ray at a time. The readable
// reference the wavefront driver (wavefront_integrator.h) is tested against.
template <bool kDistributed, uint32_t kFeatures>
Spectrum integrate(const Scene& scene, const IntegratorSettings& settings, Ray ray,
                   Sampler& sampler, PathCounters& counters, FirstHit* first) {
  PathState s(ray);
  for (;;) {
    SurfaceHit hit;
    ++counters.rays;
    if (!scene.intersect(s.ray, &hit)) {
      path_escaped<kDistributed, kFeatures>(scene, s, first);
      break;
    }
    ShadowQuery shadow;
    bool has_shadow;
    const bool goes_on =
        path_hit<kDistributed, kFeatures>(scene, settings, s, hit, sampler, counters, first, &shadow, &has_shadow);
    if (has_shadow && !scene.occluded(shadow.ray.origin, shadow.ray.direction, shadow.ray.t_max, shadow.ray.time))
      s.radiance += shadow.contribution;
    if (!goes_on) break;
  }
  return s.radiance;
}

template <bool kDistributed, uint32_t kFeatures>
struct ScalarKernel {
  static constexpr IntegrateFn fn = &integrate<kDistributed, kFeatures>;
};
using ScalarInstantiations = FeatureInstantiations<IntegrateFn, ScalarKernel>;

}  // namespace

uint32_t integrator_feature_mask(const SceneFeatures& f, IntegratorKind kind) {
  uint32_t mask = 0;
  if (f.absorption) mask |= kFeatureAbsorption;
  // An absorbing material is a dielectric, so absorption implies transmission.
  if (f.transmission) mask |= kFeatureTransmission;
  if (f.environment) mask |= kFeatureEnvironment;
  // The path integrator leaves some lights to BSDF sampling (next_event_lights).
  if (kind == IntegratorKind::kDistributed ? f.lights : f.mis_lights) mask |= kFeatureLights;
  return mask;
}

IntegrateFn select_integrator(IntegratorKind kind, const SceneFeatures& features) {
  return ScalarInstantiations::select(kind, integrator_feature_mask(features, kind));
}

IntegrateFn select_generic_integrator(IntegratorKind kind) {
  return ScalarInstantiations::select(kind, kFeatureAll);
}

}  // namespace penumbra
