#pragma once
// A baseline for the speed benchmark: Embree alone tracing the same kind of rays the path tracer
// traces on the same scene (camera rays, shadow rays towards the emitters, cosine-distributed
// bounce rays), with no shading, sampling or film work. The renderer's rays/s divided by this
// is the share of time it spends on ray casting rather than its own overhead. It traces the
// renderer's own Embree scene, so both use the same triangle test: the robust (watertight) one,
// with the exact-t hit filter attached to every triangle geometry (renderer/scene.cpp).
#include <cstdint>

#include "renderer/scene/scene.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

struct BaselineResult {
  uint64_t rays = 0;
  double seconds = 0.0;
  double mrays_per_second() const { return seconds > 0 ? rays / seconds * 1e-6 : 0.0; }
};

BaselineResult trace_embree_baseline(const Scene& scene, const RenderSettings& settings);

}  // namespace penumbra
