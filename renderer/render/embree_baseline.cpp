#include "renderer/render/embree_baseline.h"

#include <embree3/rtcore.h>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>

#include "renderer/core/flush_denormals.h"
#include "renderer/core/frame.h"
#include "renderer/sampling/sampler.h"
#include "renderer/sampling/sampling.h"
#include "renderer/lights/area_light.h"
#include "renderer/render/thin_lens_camera.h"

namespace penumbra {

BaselineResult trace_embree_baseline(const Scene& scene, const RenderSettings& settings) {
  const ThinLensCamera camera(scene.camera(), settings.width, settings.height);
  const int max_depth = settings.max_depth < 0 ? 64 : settings.max_depth;
  // Shadow-ray targets: the emitters' centres (or a point above the scene if there are none).
  std::vector<vec3> targets;
  for (uint32_t i = 0; i < scene.object_count(); ++i)
    if (const AreaLight* light = scene.object(i).area_light)
      targets.push_back(light->shape().reference_point());
  const Bounds3& bounds = scene.bounds();
  if (targets.empty()) targets.push_back(bounds.hi + (bounds.hi - bounds.lo));

  std::atomic<uint64_t> total_rays{0};
  const auto start = std::chrono::steady_clock::now();
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, settings.height, 16, 0, settings.width, 16), [&](const auto& r) {
          const FlushDenormals flush_denormals;  // the render threads' mode (render.cpp)
          Sampler sampler(settings.seed);
          uint64_t rays = 0;
          for (int y = r.rows().begin(); y < r.rows().end(); ++y)
            for (int x = r.cols().begin(); x < r.cols().end(); ++x)
              for (int s = 0; s < settings.spp; ++s) {
                sampler.start_pixel_sample(x, y, uint32_t(s));
                const CameraRay cr =
                    camera.generate_ray(vec2(x, y) + sampler.get_2d(), vec2(0.5f), 0.f);
                vec3 org = cr.origin, dir = cr.direction;
                for (int depth = 1; depth <= max_depth; ++depth) {
                  // Rays from a surface through the exact-t context filter, as the renderer
                  // traces them (scene/exact_t_check.h); the camera ray through Embree alone.
                  ExactTContext exact = scene.exact_t_check().context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
                  RTCIntersectContext plain;
                  rtcInitIntersectContext(&plain);
                  RTCIntersectContext* ctx = depth == 1 ? &plain : &exact.embree;
                  RTCRayHit rh{};
                  rh.ray.org_x = org.x, rh.ray.org_y = org.y, rh.ray.org_z = org.z;
                  rh.ray.dir_x = dir.x, rh.ray.dir_y = dir.y, rh.ray.dir_z = dir.z;
                  rh.ray.tnear = 0.f;
                  rh.ray.tfar = kInfinity;
                  rh.ray.mask = 0xFFFFFFFFu;
                  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                  ++rays;
                  rtcIntersect1(scene.embree_scene(), ctx, &rh);
                  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || depth == max_depth) break;
                  const vec3 p = org + dir * rh.ray.tfar;
                  vec3 n = glm::normalize(vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
                  if (glm::dot(n, dir) > 0.f) n = -n;
                  const vec3 origin = p + n * 1e-4f;
                  const vec3 target = targets[size_t(sampler.get_1d() * targets.size()) % targets.size()];
                  const vec3 to = target - origin;
                  const float dist = glm::length(to);
                  RTCRay shadow{};
                  shadow.org_x = origin.x, shadow.org_y = origin.y, shadow.org_z = origin.z;
                  shadow.dir_x = to.x / dist, shadow.dir_y = to.y / dist, shadow.dir_z = to.z / dist;
                  shadow.tnear = 0.f;
                  shadow.tfar = dist * 0.999f;
                  shadow.mask = 0xFFFFFFFFu;
                  ++rays;
                  rtcOccluded1(scene.embree_scene(), &exact.embree, &shadow);
                  org = origin;
                  dir = glm::normalize(Frame(n).to_world(square_to_cosine_hemisphere(sampler.get_2d())));
                }
              }
          total_rays += rays;
        });
  });
  BaselineResult result;
  result.rays = total_rays.load();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace penumbra
