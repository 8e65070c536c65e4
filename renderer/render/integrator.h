#pragma once
// Integrators: estimate the radiance arriving along a camera ray.
//  * path: unidirectional path tracing with next-event estimation and multiple importance
//    sampling (Veach 1997 ch. 9, power heuristic), Russian roulette from rr_depth.
//  * distributed: Cook, Porter & Carpenter 1984 on Whitted 1980 -- direct light at every hit,
//    recursion only through glossy, specular and transmissive lobes; a diffuse lobe ends the path.
#include <cstdint>

#include "renderer/core/math.h"
#include "renderer/core/ray.h"
#include "renderer/render/output_layers.h"
#include "renderer/render/path_step.h"
#include "renderer/sampling/sampler.h"
#include "renderer/scene/scene.h"

namespace penumbra {

// `first`, when not null, receives the camera ray's first hit for the output layers
// (output_layers.h); null when the render asks for none.
using IntegrateFn = Spectrum (*)(const Scene& scene, const IntegratorSettings& settings,
                                 Ray ray, Sampler& sampler, PathCounters& counters,
                                 FirstHit* first);

// The integrator specialised on the features the scene uses (chosen once per render): code for
// an absent feature (absorption, refraction, environment, lights) is compiled out.
IntegrateFn select_integrator(IntegratorKind kind, const SceneFeatures& features);
// The instantiation with every feature compiled in (tests check the specialised ones against it).
IntegrateFn select_generic_integrator(IntegratorKind kind);
// The feature bits select_integrator compiles in for a scene (for tests and benchmarks).
uint32_t integrator_feature_mask(const SceneFeatures& features, IntegratorKind kind);

}  // namespace penumbra
