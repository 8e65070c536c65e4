#include "renderer/render/embree_ray_forms.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "renderer/core/flush_denormals.h"
#include "renderer/core/frame.h"
#include "renderer/embree/ray_access.h"
#include "renderer/lights/area_light.h"
#include "renderer/render/thin_lens_camera.h"
#include "renderer/sampling/sampler.h"
#include "renderer/sampling/sampling.h"
#include "renderer/shapes/shape.h"

namespace penumbra {
namespace {

constexpr unsigned kPacket = 16;
// Rays handed to one task: a multiple of the packet width, and large enough for a stream call
// to have rays to reorder (Embree splits streams into packets of coherent rays internally).
constexpr size_t kChunk = 256;
// Enough rays for a stable rate; more would only cost memory (each RTCRayHit is 80 bytes).
constexpr size_t kMaxCameraRays = size_t(1) << 20;

struct RaySet {
  std::vector<RTCRayHit> rays;  // for shadow rays only .ray is used
  bool occlusion = false;
  bool coherent = false;
  // Rays that leave a surface: traced with the scene's exact-t context filter, as the renderer
  // traces them (scene/exact_t_check.h), or they would stop on the surface they leave.
  bool from_surface = false;
};

RTCRayHit make_ray(const vec3& o, const vec3& d, float t_max, float time) {
  return embree_ray_hit(Ray{o, d, time, t_max});
}

// Camera rays for the pixel samples; for each that hits, a shadow ray to an emitter (chosen
// uniformly among the area lights' reference points, as the Embree-only baseline does) and a
// cosine-distributed bounce ray, both spawned with the renderer's own offsets.
void make_rays(const Scene& scene, const RenderSettings& settings, RaySet* camera_rays,
               RaySet* shadow_rays, RaySet* bounce_rays) {
  const ThinLensCamera camera(scene.camera(), settings.width, settings.height);
  std::vector<vec3> targets;
  for (uint32_t i = 0; i < scene.object_count(); ++i)
    if (const AreaLight* light = scene.object(i).area_light)
      targets.push_back(light->shape().reference_point());
  const Bounds3& bounds = scene.bounds();
  if (targets.empty()) targets.push_back(bounds.hi + (bounds.hi - bounds.lo));
  const bool lens = scene.features().lens;
  Sampler sampler(settings.seed);
  const size_t wanted = size_t(settings.width) * size_t(settings.height) * size_t(std::max(1, settings.spp));
  const int spp = int(std::min(wanted, kMaxCameraRays) / (size_t(settings.width) * settings.height));
  for (int y = 0; y < settings.height; ++y)
    for (int x = 0; x < settings.width; ++x)
      for (int s = 0; s < std::max(1, spp); ++s) {
        sampler.start_pixel_sample(x, y, uint32_t(s));
        const vec2 film = vec2(float(x), float(y)) + sampler.get_2d();
        const CameraRay cr = camera.generate_ray(film, lens ? sampler.get_2d() : vec2(0.5f), 0.f);
        const Ray ray{cr.origin, cr.direction, 0.f};
        camera_rays->rays.push_back(make_ray(ray.origin, ray.direction, kInfinity, 0.f));
        SurfaceHit hit;
        if (!scene.intersect(ray, &hit)) continue;
        const vec3 n = glm::dot(hit.ng, ray.direction) < 0.f ? hit.ng : -hit.ng;
        const vec3 target = targets[size_t(sampler.get_1d() * float(targets.size())) % targets.size()];
        const vec3 shadow_origin = offset_ray_origin(hit.p, hit.p_error, hit.ng, target - hit.p);
        const vec3 to = target - shadow_origin;
        const float dist = glm::length(to);
        if (dist > 0.f)
          shadow_rays->rays.push_back(make_ray(shadow_origin, to / dist, dist * (1.f - kShadowEpsilon), 0.f));
        const vec3 wo = Frame(n).to_world(square_to_cosine_hemisphere(sampler.get_2d()));
        bounce_rays->rays.push_back(
            make_ray(offset_ray_origin(hit.p, hit.p_error, hit.ng, wo), wo, kInfinity, 0.f));
      }
  camera_rays->coherent = true;
  shadow_rays->occlusion = true;
  shadow_rays->from_surface = true;
  bounce_rays->from_surface = true;
}

void to_packet(const RTCRayHit* in, unsigned count, RTCRayHit16* out, int* valid) {
  for (unsigned i = 0; i < kPacket; ++i) {
    valid[i] = i < count ? -1 : 0;
    const RTCRay& r = in[std::min(i, count - 1)].ray;
    RTCRay16& p = out->ray;
    p.org_x[i] = r.org_x, p.org_y[i] = r.org_y, p.org_z[i] = r.org_z;
    p.dir_x[i] = r.dir_x, p.dir_y[i] = r.dir_y, p.dir_z[i] = r.dir_z;
    p.tnear[i] = r.tnear, p.tfar[i] = r.tfar, p.time[i] = r.time;
    p.mask[i] = r.mask, p.id[i] = r.id, p.flags[i] = r.flags;
    out->hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    out->hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
}

// Embree requires the valid mask, like the packet, to be aligned to the packet's size.
struct alignas(64) ValidMask {
  int lanes[kPacket];
  int* data() { return lanes; }
};

struct Packets {
  std::vector<RTCRayHit16> rays;
  std::vector<ValidMask> valid;
};

Packets make_packets(const std::vector<RTCRayHit>& rays) {
  Packets p;
  const size_t n = (rays.size() + kPacket - 1) / kPacket;
  p.rays.resize(n);
  p.valid.resize(n);
  for (size_t k = 0; k < n; ++k)
    to_packet(&rays[k * kPacket], unsigned(std::min<size_t>(kPacket, rays.size() - k * kPacket)), &p.rays[k],
              p.valid[k].data());
  return p;
}

// Camera rays go through Embree alone, as the renderer's first trace of them does; rays from a
// surface through the exact-t context filter (the renderer's retrace and occlusion queries).
ExactTContext make_context(const Scene& scene, const RaySet& set) {
  const RTCIntersectContextFlags flags =
      set.coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  if (set.from_surface) return scene.exact_t_check().context(flags);
  ExactTContext c{};
  rtcInitIntersectContext(&c.embree);
  c.embree.flags = flags;
  return c;
}

// Traces a working copy of `set` in `form` on every thread of `arena`; returns seconds and
// counts the hits.
double trace(const Scene& source, const RaySet& set, RayForm form, tbb::task_arena& arena, uint64_t* hits) {
  RTCScene scene = source.embree_scene();
  std::vector<RTCRayHit> rays = set.rays;  // tracing overwrites tfar and the hit
  Packets packets = form == RayForm::kPacket16 ? make_packets(set.rays) : Packets{};
  const size_t chunks = (rays.size() + kChunk - 1) / kChunk;
  const auto start = std::chrono::steady_clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks), [&](const tbb::blocked_range<size_t>& r) {
      const FlushDenormals flush_denormals;  // the render threads' mode (render.cpp)
      ExactTContext context = make_context(source, set);
      RTCIntersectContext* ctx = &context.embree;
      for (size_t c = r.begin(); c != r.end(); ++c) {
        const size_t lo = c * kChunk, hi = std::min(rays.size(), lo + kChunk);
        switch (form) {
          case RayForm::kSingle:
            for (size_t i = lo; i < hi; ++i) {
              if (set.occlusion) rtcOccluded1(scene, ctx, &rays[i].ray);
              else rtcIntersect1(scene, ctx, &rays[i]);
            }
            break;
          case RayForm::kPacket16:
            for (size_t k = lo / kPacket; k < (hi + kPacket - 1) / kPacket; ++k) {
              if (set.occlusion) rtcOccluded16(packets.valid[k].data(), scene, ctx, &packets.rays[k].ray);
              else rtcIntersect16(packets.valid[k].data(), scene, ctx, &packets.rays[k]);
            }
            break;
          case RayForm::kStream:
            if (set.occlusion) rtcOccluded1M(scene, ctx, &rays[lo].ray, unsigned(hi - lo), sizeof(RTCRayHit));
            else rtcIntersect1M(scene, ctx, &rays[lo], unsigned(hi - lo), sizeof(RTCRayHit));
            break;
        }
      }
    });
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  uint64_t n = 0;
  if (form == RayForm::kPacket16) {
    for (size_t i = 0; i < rays.size(); ++i) {
      const RTCRayHit16& p = packets.rays[i / kPacket];
      const size_t lane = i % kPacket;
      n += set.occlusion ? p.ray.tfar[lane] < 0.f : p.hit.geomID[lane] != RTC_INVALID_GEOMETRY_ID;
    }
  } else {
    for (const RTCRayHit& r : rays)
      n += set.occlusion ? r.ray.tfar < 0.f : r.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }
  *hits = n;
  return seconds;
}

}  // namespace

const char* ray_kind_name(RayKind kind) {
  switch (kind) {
    case RayKind::kCamera: return "camera";
    case RayKind::kShadow: return "shadow";
    case RayKind::kBounce: return "bounce";
  }
  return "?";
}

const char* ray_form_name(RayForm form) {
  switch (form) {
    case RayForm::kSingle: return "single (rtc*1)";
    case RayForm::kPacket16: return "packet (rtc*16)";
    case RayForm::kStream: return "stream (rtc*1M)";
  }
  return "?";
}

std::vector<RayFormResult> trace_embree_ray_forms(const Scene& scene, const RenderSettings& settings,
                                                  int repeat) {
  RaySet sets[3];
  make_rays(scene, settings, &sets[0], &sets[1], &sets[2]);
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  std::vector<RayFormResult> results;
  for (RayKind kind : {RayKind::kCamera, RayKind::kShadow, RayKind::kBounce}) {
    const RaySet& set = sets[int(kind)];
    for (RayForm form : {RayForm::kSingle, RayForm::kPacket16, RayForm::kStream}) {
      RayFormResult r{kind, form};
      r.rays = set.rays.size();
      r.seconds = INFINITY;
      for (int i = 0; i < std::max(1, repeat); ++i) r.seconds = std::min(r.seconds, trace(scene, set, form, arena, &r.hits));
      results.push_back(r);
    }
  }
  return results;
}

}  // namespace penumbra
