#include "renderer/scene/scene_impl.h"

namespace penumbra {

vec3 ObjectRecord::moving_displacement_at(float time, float shutter_open, float shutter_span) const {
  if (kind == Kind::kSphere) return motion.displacement(shutter_open + time * shutter_span);
  // Embree interpolates vertex buffers linearly between evenly spread time steps.
  const float f = std::clamp(time, 0.f, 1.f) * float(time_steps - 1);
  const int i = std::min(int(f), time_steps - 2);
  const float w = f - float(i);
  return glm::mix(step_displacement[i], step_displacement[i + 1], w);
}

SceneImpl::~SceneImpl() {
  if (rtc_scene) rtcReleaseScene(rtc_scene);
}

bool SceneImpl::intersect(const Ray& ray, SurfaceHit* hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.dir_x = ray.direction.x;
  rh.ray.dir_y = ray.direction.y;
  rh.ray.dir_z = ray.direction.z;
  rh.ray.tnear = 0.f;
  rh.ray.tfar = ray.t_max;
  rh.ray.time = ray.time;
  rh.ray.mask = 0xFFFFFFFFu;  // Debian's Embree is built with ray masks: 0 would hit nothing
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rtc_scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

  const ObjectRecord& obj = objects[rh.hit.geomID];
  hit->t = rh.ray.tfar;
  hit->object = rh.hit.geomID;
  hit->primitive = rh.hit.primID;
  const vec3 disp = obj.displacement_at(ray.time, shutter_open, shutter_span);
  if (obj.kind == ObjectRecord::Kind::kSphere) {
    sphere_hit_geometry(obj.center + disp, obj.radius, ray.origin + ray.direction * hit->t, hit);
    return true;
  }
  // Rebuild the point from the barycentrics rather than o + t*d, whose error grows with t
  // (pbrt-v4 section 6.8.4 bounds the barycentric sum by gamma(7)).
  const uint32_t* tri = &obj.indices[size_t(rh.hit.primID) * 3];
  const vec3 p0 = obj.positions[tri[0]] + disp;
  const vec3 p1 = obj.positions[tri[1]] + disp;
  const vec3 p2 = obj.positions[tri[2]] + disp;
  const float b1 = rh.hit.u, b2 = rh.hit.v, b0 = 1.f - b1 - b2;
  const vec3 t0 = b0 * p0, t1 = b1 * p1, t2 = b2 * p2;
  hit->p = t0 + t1 + t2;
  hit->p_error = gamma_bound(7) * (glm::abs(t0) + glm::abs(t1) + glm::abs(t2));
  vec3 ng = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(ng);
  ng = len > 0.f ? ng / len : vec3(0.f, 0.f, 1.f);
  hit->ng = ng;
  hit->ns = ng;
  if (!obj.normals.empty()) {
    vec3 ns = b0 * obj.normals[tri[0]] + b1 * obj.normals[tri[1]] + b2 * obj.normals[tri[2]];
    const float ls = glm::length(ns);
    if (ls > 0.f && std::isfinite(ls)) {
      ns /= ls;
      hit->ns = glm::dot(ns, ng) < 0.f ? -ns : ns;
    }
  }
  return true;
}

bool SceneImpl::occluded(const vec3& origin, const vec3& dir, float t_max, float time) const {
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
  rtcOccluded1(rtc_scene, &context, &r);
  return r.tfar < 0.f;
}

}  // namespace penumbra
