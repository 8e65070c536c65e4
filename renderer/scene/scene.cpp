#include "renderer/scene/scene.h"

#include <embree3/rtcore.h>

#include <cstddef>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "renderer/embree/ray_access.h"
#include "renderer/lights/light.h"
#include "renderer/materials/coating_tables.h"
#include "renderer/shapes/shape.h"
#include "renderer/textures/texture_image_cache.h"

namespace penumbra {

Scene::~Scene() {
  if (rtc_scene_) rtcReleaseScene(rtc_scene_);
}

bool Scene::intersect(const Ray& ray, SurfaceHit* hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh = embree_ray_hit(ray);
  rtcIntersect1(rtc_scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  // A re-hit of the surface the ray leaves: trace again with the test on every candidate
  // (scene/exact_t_check.h).
  if (exact_t_.rejects(rh.hit.geomID, rh.hit.instID[0], rh.hit.primID, ray.origin, ray.direction,
                       ray.time)) {
    rh = exact_t_retrace(rtc_scene_, exact_t_, ray);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  }
  complete_hit(ray, rh.ray.tfar, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID,
               vec2(rh.hit.u, rh.hit.v), hit);
  return true;
}

void Scene::complete_hit(const Ray& ray, float t, uint32_t geom_id, uint32_t inst_id,
                         uint32_t prim_id, vec2 uv, SurfaceHit* hit) const {
  hit->t = t;
  hit->primitive = prim_id;
  if (inst_id != RTC_INVALID_GEOMETRY_ID) {  // a copy: geom_id is the mesh's id in it
    const Instance& copy = instances_[inst_id - objects_.size()];
    hit->object = copy.object();
    hit->instance = inst_id - uint32_t(objects_.size());
    copy.hit_geometry(ray, t, prim_id, uv, hit);
    return;
  }
  hit->object = geom_id;
  hit->instance = SurfaceHit::kNotACopy;
  objects_[geom_id].shape->hit_geometry(ray, t, prim_id, uv, hit);
}

namespace {

// Lanes [0, count) of a 16-wide packet hold rays[0, count); the rest are switched off (and
// hold a copy of ray 0).
template <typename Packet>
void fill_packet_rays(const Ray* rays, int count, int* valid, Packet* r) {
  for (int i = 0; i < Scene::kPacketSize; ++i) {
    valid[i] = i < count ? -1 : 0;
    r->tnear[i] = 0.f;
    r->mask[i] = 0xFFFFFFFFu;  // Debian's Embree is built with ray masks: 0 would hit nothing
    r->id[i] = unsigned(i);
    r->flags[i] = 0;
  }
#if defined(__SSE2__)
  // A Ray is eight floats (origin, direction, time, t_max): four rays at a time as two 4x4
  // transposes (SSE2, every x86-64 CPU), 16 loads, shuffles and stores instead of 48 scalar
  // stores scattered over the packet's arrays (a fifth of the ray tracing calls' own time).
  static_assert(sizeof(Ray) == 8 * sizeof(float) && offsetof(Ray, direction) == 12 &&
                    offsetof(Ray, time) == 24 && offsetof(Ray, t_max) == 28,
                "Ray's layout, as the transposes read it");
  for (int g = 0; g < Scene::kPacketSize; g += 4) {
    __m128 a[4], b[4];
    for (int j = 0; j < 4; ++j) {
      const float* f = &rays[g + j < count ? g + j : 0].origin.x;
      a[j] = _mm_loadu_ps(f);      // ox oy oz dx
      b[j] = _mm_loadu_ps(f + 4);  // dy dz time t_max
    }
    _MM_TRANSPOSE4_PS(a[0], a[1], a[2], a[3]);
    _MM_TRANSPOSE4_PS(b[0], b[1], b[2], b[3]);
    _mm_storeu_ps(&r->org_x[g], a[0]);
    _mm_storeu_ps(&r->org_y[g], a[1]);
    _mm_storeu_ps(&r->org_z[g], a[2]);
    _mm_storeu_ps(&r->dir_x[g], a[3]);
    _mm_storeu_ps(&r->dir_y[g], b[0]);
    _mm_storeu_ps(&r->dir_z[g], b[1]);
    _mm_storeu_ps(&r->time[g], b[2]);
    _mm_storeu_ps(&r->tfar[g], b[3]);
  }
#else
  for (int i = 0; i < Scene::kPacketSize; ++i) {
    const Ray& ray = rays[i < count ? i : 0];
    r->org_x[i] = ray.origin.x;
    r->org_y[i] = ray.origin.y;
    r->org_z[i] = ray.origin.z;
    r->dir_x[i] = ray.direction.x;
    r->dir_y[i] = ray.direction.y;
    r->dir_z[i] = ray.direction.z;
    r->tfar[i] = ray.t_max;
    r->time[i] = ray.time;
  }
#endif
}

}  // namespace

void Scene::intersect_packet(const Ray* rays, int count, bool coherent, SurfaceHit* hits,
                             bool* found) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) int valid[kPacketSize];
  alignas(64) RTCRayHit16 rh;
  fill_packet_rays(rays, count, valid, &rh.ray);
  for (int i = 0; i < kPacketSize; ++i) {
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect16(valid, rtc_scene_, &context, &rh);
  for (int i = 0; i < count; ++i) {
    found[i] = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    if (!found[i]) continue;
    if (exact_t_.rejects(rh.hit.geomID[i], rh.hit.instID[0][i], rh.hit.primID[i], rays[i].origin,
                         rays[i].direction, rays[i].time)) {
      // A re-hit of the surface the ray leaves: trace this ray again, alone, with the test on
      // every candidate (scene/exact_t_check.h).
      const RTCRayHit one = exact_t_retrace(rtc_scene_, exact_t_, rays[i]);
      found[i] = one.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      if (found[i])
        complete_hit(rays[i], one.ray.tfar, one.hit.geomID, one.hit.instID[0], one.hit.primID,
                     vec2(one.hit.u, one.hit.v), &hits[i]);
      continue;
    }
    complete_hit(rays[i], rh.ray.tfar[i], rh.hit.geomID[i], rh.hit.instID[0][i], rh.hit.primID[i],
                 vec2(rh.hit.u[i], rh.hit.v[i]), &hits[i]);
  }
}

void Scene::occluded_packet(const Ray* rays, int count, bool* occluded) const {
  // Occlusion runs the exact-t test on every candidate (scene/exact_t_check.h).
  ExactTContext context = exact_t_.context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
  alignas(64) int valid[kPacketSize];
  alignas(64) RTCRay16 r;
  fill_packet_rays(rays, count, valid, &r);
  rtcOccluded16(valid, rtc_scene_, &context.embree, &r);
  for (int i = 0; i < count; ++i) occluded[i] = r.tfar[i] < 0.f;
}

void Scene::surface_derivatives(float time, SurfaceHit* hit) const {
  if (hit->instance != SurfaceHit::kNotACopy)
    instances_[hit->instance].surface_derivatives(time, hit);
  else
    objects_[hit->object].shape->surface_derivatives(time, hit);
}

bool Scene::occluded(const vec3& origin, const vec3& dir, float t_max, float time) const {
  ExactTContext context = exact_t_.context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
  RTCRay r;
  r.org_x = origin.x;
  r.org_y = origin.y;
  r.org_z = origin.z;
  r.dir_x = dir.x;
  r.dir_y = dir.y;
  r.dir_z = dir.z;
  r.tnear = 0.f;
  r.tfar = t_max;
  r.time = time;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(rtc_scene_, &context.embree, &r);
  return r.tfar < 0.f;
}

}  // namespace penumbra
