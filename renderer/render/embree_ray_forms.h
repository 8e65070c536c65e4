#pragma once
// What Embree alone can do with a scene's rays, in each of its three calling forms: the same
// pre-generated rays traced one at a time (rtcIntersect1 / rtcOccluded1), in 16-wide packets
// (rtcIntersect16 / rtcOccluded16) and as streams (rtcIntersect1M / rtcOccluded1M). Three kinds
// of rays, because the forms pay off differently on each (issue 11): coherent camera rays,
// shadow rays from their first hits towards the emitters, and incoherent cosine-distributed
// bounce rays from the same hits. Only tracing is timed: generating the rays and copying them
// into packets happens before the clock starts. `penumbra bench` prints the table beside the
// renderer's own rays/s.
#include <cstdint>
#include <vector>

#include "renderer/scene/scene.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

enum class RayKind { kCamera, kShadow, kBounce };
enum class RayForm { kSingle, kPacket16, kStream };

const char* ray_kind_name(RayKind kind);
const char* ray_form_name(RayForm form);

struct RayFormResult {
  RayKind kind;
  RayForm form;
  uint64_t rays = 0;
  uint64_t hits = 0;  // hits (or occluded rays): the same in every form, a check they agree
  double seconds = 0.0;
  double mrays_per_second() const { return seconds > 0 ? rays / seconds * 1e-6 : 0.0; }
};

// One camera ray per pixel sample of `settings` (its size, spp, seed and threads), the shadow
// and bounce rays of those that hit; each kind traced in each form, `repeat` times (the best
// time is kept). Results in kind-major order.
std::vector<RayFormResult> trace_embree_ray_forms(const Scene& scene, const RenderSettings& settings,
                                                  int repeat = 1);

}  // namespace penumbra
