#include "renderer/scene/scene.h"

#include <embree3/rtcore.h>

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

  hit->t = rh.ray.tfar;
  hit->primitive = rh.hit.primID;
  if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {  // a copy: geomID is the mesh's id in it
    const Instance& copy = instances_[rh.hit.instID[0] - objects_.size()];
    hit->object = copy.object();
    hit->instance = rh.hit.instID[0] - uint32_t(objects_.size());
    copy.hit_geometry(ray, hit->t, rh.hit.primID, vec2(rh.hit.u, rh.hit.v), hit);
    return true;
  }
  hit->object = rh.hit.geomID;
  hit->instance = SurfaceHit::kNotACopy;
  objects_[rh.hit.geomID].shape->hit_geometry(ray, hit->t, rh.hit.primID, vec2(rh.hit.u, rh.hit.v),
                                              hit);
  return true;
}

void Scene::surface_derivatives(float time, SurfaceHit* hit) const {
  if (hit->instance != SurfaceHit::kNotACopy)
    instances_[hit->instance].surface_derivatives(time, hit);
  else
    objects_[hit->object].shape->surface_derivatives(time, hit);
}

bool Scene::occluded(const vec3& origin, const vec3& dir, float t_max, float time) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
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
  rtcOccluded1(rtc_scene_, &context, &r);
  return r.tfar < 0.f;
}

}  // namespace penumbra
