#include "renderer/scene/scene.h"

#include <numeric>

#include "renderer/scene/embree_device.h"
#include "renderer/scene/scene_impl.h"

namespace penumbra {
namespace {

// ---- Spheres as Embree user geometry: the exact quadratic motion path needs our own test. ----

void sphere_bounds_fn(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  const SceneImpl& scene = *data->scene;
  const ObjectRecord& obj = scene.objects[data->object];
  vec3 lo(0.f), hi(0.f);
  // One static box around the whole swept path over the shutter: Embree's linear motion of
  // boxes between time steps cannot contain a quadratic path in general.
  obj.motion.displacement_bounds(scene.shutter_open, scene.shutter_open + scene.shutter_span, &lo,
                                 &hi);
  const vec3 r(obj.radius * (1.f + 4.f * gamma_bound(4)));
  RTCBounds* b = args->bounds_o;
  b->lower_x = obj.center.x + lo.x - r.x;
  b->lower_y = obj.center.y + lo.y - r.y;
  b->lower_z = obj.center.z + lo.z - r.z;
  b->upper_x = obj.center.x + hi.x + r.x;
  b->upper_y = obj.center.y + hi.y + r.y;
  b->upper_z = obj.center.z + hi.z + r.z;
}

vec3 ray_origin(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i));
}
vec3 ray_direction(RTCRayN* ray, unsigned n, unsigned i) {
  return vec3(RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i));
}

void sphere_intersect_fn(const RTCIntersectFunctionNArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  const SceneImpl& scene = *data->scene;
  const ObjectRecord& obj = scene.objects[data->object];
  RTCRayHitN* rayhit = args->rayhit;
  RTCRayN* ray = RTCRayHitN_RayN(rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const vec3 o = ray_origin(ray, args->N, i), d = ray_direction(ray, args->N, i);
    const float time = RTCRayN_time(ray, args->N, i);
    const float t_near = RTCRayN_tnear(ray, args->N, i);
    float& t_far = RTCRayN_tfar(ray, args->N, i);
    const vec3 c = obj.center + obj.displacement_at(time, scene.shutter_open, scene.shutter_span);
    const float t = intersect_sphere(c, obj.radius, o, d, t_far);
    if (t <= t_near) continue;
    t_far = t;
    const vec3 n = o + t * d - c;
    RTCHitN_Ng_x(hit, args->N, i) = n.x;
    RTCHitN_Ng_y(hit, args->N, i) = n.y;
    RTCHitN_Ng_z(hit, args->N, i) = n.z;
    RTCHitN_u(hit, args->N, i) = 0.f;
    RTCHitN_v(hit, args->N, i) = 0.f;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

void sphere_occluded_fn(const RTCOccludedFunctionNArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  const SceneImpl& scene = *data->scene;
  const ObjectRecord& obj = scene.objects[data->object];
  RTCRayN* ray = args->ray;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const vec3 o = ray_origin(ray, args->N, i), d = ray_direction(ray, args->N, i);
    const float time = RTCRayN_time(ray, args->N, i);
    float& t_far = RTCRayN_tfar(ray, args->N, i);
    const vec3 c = obj.center + obj.displacement_at(time, scene.shutter_open, scene.shutter_span);
    const float t = intersect_sphere(c, obj.radius, o, d, t_far);
    if (t > RTCRayN_tnear(ray, args->N, i)) t_far = -kInfinity;
  }
}

// ---- Triangles: Embree's robust (watertight) test, with the sign of t settled exactly. ----
//
// Debian's Embree, like any, tests triangles by default with Moeller-Trumbore on precomputed
// edges: not watertight, so shadow rays slip through edges two triangles share and a light in
// the corner of a closed box leaks (tests/stress LightLeak). RTC_SCENE_FLAG_ROBUST switches to
// its Pluecker test, whose edge functions are computed the same way for both triangles of an
// edge, so no ray falls between them (Embree kernels/geometry/triangle_intersector_pluecker.h).
//
// Neither test bounds the rounding error of its own t, as pbrt-v4's triangle test does (it
// rejects t <= deltaT, section 6.8.7); our spawn offsets (ray.h, pbrt-v4 section 6.8.6) cover
// only the error of the hit point, so two cases re-hit the triangle a ray leaves:
//  - The robust test accepts tnear <= t (inclusive). A hit point that is exact has a zero error
//    bound and so a zero offset (any point of a quad in the plane y = 0): the ray starts on the
//    plane, t computes to exactly 0 and is accepted; every such quad shadows itself entirely.
//  - Embree computes the plane distance from vertices translated to the ray origin, with an
//    error of order eps * (distance of the triangle's first vertex from the origin). Where a
//    large triangle reaches close to the world origin that exceeds our offset, which scales with
//    the hit point's coordinates: 36-58% of the rays spawned near such a corner hit the triangle
//    again, with either Embree test (tests/stress LargeTriangleNearOrigin).
// So each triangle hit Embree reports passes this filter, which re-evaluates the sign of
// t = ((p0 - o) . n) / (d . n) in double precision from the same float vertices our hit points
// are rebuilt from, and keeps the hit only if t > 0. The doubles hold the float inputs' products
// with 2^-53 relative error, so the sign is right for any origin further than about 1e-15 of
// the triangle's size from its plane (over the sine of its angle at p0 for a sliver), far
// below any spawn offset: no error bound of Embree's internals is needed, any triangle is
// covered (the one left, its coplanar neighbour in a quad, a larger neighbour), and since a hit
// with t > 0 is never dropped, watertightness stays.
inline void filter_triangle_hit(const RTCFilterFunctionNArguments* args, unsigned n, unsigned i) {
  if (args->valid[i] == 0) return;
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  const SceneImpl& scene = *data->scene;
  const ObjectRecord& obj = scene.objects[data->object];
  const uint32_t* tri = obj.indices.data() + size_t(RTCHitN_primID(args->hit, n, i)) * 3;
  // The same float vertices SceneImpl::intersect rebuilds hit points from.
  vec3 a = obj.positions[tri[0]], b = obj.positions[tri[1]], c = obj.positions[tri[2]];
  if (obj.time_steps > 1) {  // moving (static and shutter-less objects have one step)
    const vec3 disp = obj.moving_displacement_at(RTCRayN_time(args->ray, n, i), scene.shutter_open,
                                                 scene.shutter_span);
    a += disp;
    b += disp;
    c += disp;
  }
  const dvec3 p0(a), normal = glm::cross(dvec3(b) - p0, dvec3(c) - p0);
  const double num = glm::dot(p0 - dvec3(ray_origin(args->ray, n, i)), normal);
  const double den = glm::dot(dvec3(ray_direction(args->ray, n, i)), normal);
  // Signs compared, not num * den > 0, which could underflow to 0 in a tiny scene.
  const bool ahead = (num > 0.0 && den > 0.0) || (num < 0.0 && den < 0.0);
  if (!ahead) args->valid[i] = 0;
}

void triangle_filter_fn(const RTCFilterFunctionNArguments* args) {
  if (args->N == 1) {  // rtcIntersect1 / rtcOccluded1: the accessors fold to plain fields
    filter_triangle_hit(args, 1, 0);
    return;
  }
  for (unsigned i = 0; i < args->N; ++i) filter_triangle_hit(args, args->N, i);
}

// ---- Build helpers ----

// Vertex buffers at evenly spread shutter instants. Linear interpolation of the quadratic path
// between steps deviates by at most |a| dt^2 / 8; keep that below 1e-4 of the distance to the
// camera (about a seventh of a pixel at 1000 pixels over a 40 degree view), at most Embree's 129.
int motion_time_steps(const ObjectRecord& obj, float span, float camera_distance) {
  if (obj.motion.is_static() || span <= 0.f) return 1;
  const float a = glm::length(obj.motion.acceleration);
  if (a == 0.f) return 2;
  const float tolerance = std::max(1e-4f * camera_distance, 1e-12f);
  const float intervals = std::ceil(span * std::sqrt(a / (8.f * tolerance)));
  return int(std::clamp(intervals, 1.f, 128.f)) + 1;
}

float triangle_area(const vec3& a, const vec3& b, const vec3& c) {
  return 0.5f * glm::length(glm::cross(b - a, c - a));
}

}  // namespace

Scene::Scene(std::unique_ptr<SceneImpl> impl) : impl_(std::move(impl)) {}
Scene::~Scene() = default;

std::unique_ptr<Scene> Scene::build(const SceneInput& input) {
  auto impl = std::make_unique<SceneImpl>();
  SceneImpl& s = *impl;
  s.camera = input.camera;
  s.shutter_open = input.camera.shutter_open;
  s.shutter_span = std::max(0.f, input.camera.shutter_close - input.camera.shutter_open);
  s.environment = input.environment;
  s.features.lens = input.camera.aperture_radius > 0.f;
  s.features.environment = !is_black(input.environment);

  s.materials.reserve(input.materials.size());
  for (const MaterialParams& m : input.materials) {
    s.materials.emplace_back(m);
    if (const auto* d = std::get_if<DielectricParams>(&m)) {
      s.features.transmission = true;
      if (!is_black(d->absorption)) s.features.absorption = true;
    }
  }

  vec3 lo(kInfinity), hi(-kInfinity);
  s.objects.resize(input.objects.size());
  for (size_t i = 0; i < input.objects.size(); ++i) {
    const ObjectDesc& desc = input.objects[i];
    ObjectRecord& obj = s.objects[i];
    obj.material = desc.material;
    obj.emission = desc.emission;
    obj.motion = Motion{desc.velocity, desc.acceleration};
    // Without a shutter interval there is no blur: bake the place at the shutter time in.
    vec3 baked(0.f);
    if (s.shutter_span <= 0.f) {
      baked = obj.motion.displacement(s.shutter_open);
      obj.motion = Motion{};
    }
    if (const auto* sphere = std::get_if<SphereDesc>(&desc.shape)) {
      obj.kind = ObjectRecord::Kind::kSphere;
      obj.center = sphere->center + baked;
      obj.radius = sphere->radius;
      obj.area = 4.f * kPi * obj.radius * obj.radius;
      s.features.spheres = true;
    } else {
      obj.kind = ObjectRecord::Kind::kTriangles;
      s.features.triangles = true;
      if (const auto* quad = std::get_if<QuadDesc>(&desc.shape)) {
        obj.is_quad = true;
        obj.quad = *quad;
        obj.quad.origin += baked;
        const vec3 o = obj.quad.origin;
        obj.positions = {o, o + quad->u, o + quad->u + quad->v, o + quad->v};
        obj.indices = {0, 1, 2, 0, 2, 3};
        obj.area = glm::length(glm::cross(quad->u, quad->v));
      } else {
        const auto& mesh = std::get<MeshDesc>(desc.shape);
        obj.positions = mesh.positions;
        for (vec3& p : obj.positions) p += baked;
        obj.indices = mesh.indices;
        obj.normals = mesh.normals;
        const size_t n = obj.indices.size() / 3;
        std::vector<float> areas(n);
        double total = 0.0;
        for (size_t t = 0; t < n; ++t) {
          areas[t] = triangle_area(obj.positions[obj.indices[3 * t]],
                                   obj.positions[obj.indices[3 * t + 1]],
                                   obj.positions[obj.indices[3 * t + 2]]);
          total += areas[t];
        }
        obj.area = float(total);
        if (!is_black(obj.emission)) {
          obj.triangle_cdf.resize(n);
          double acc = 0.0;
          for (size_t t = 0; t < n; ++t) {
            acc += areas[t];
            obj.triangle_cdf[t] = float(acc / total);
          }
          obj.triangle_cdf.back() = 1.f;
        }
      }
    }
    if (!obj.motion.is_static()) s.features.motion = true;

    // World bounds over the shutter.
    vec3 dlo(0.f), dhi(0.f);
    obj.motion.displacement_bounds(s.shutter_open, s.shutter_open + s.shutter_span, &dlo, &dhi);
    vec3 olo, ohi;
    if (obj.kind == ObjectRecord::Kind::kSphere) {
      olo = obj.center - vec3(obj.radius);
      ohi = obj.center + vec3(obj.radius);
    } else {
      olo = vec3(kInfinity);
      ohi = vec3(-kInfinity);
      for (const vec3& p : obj.positions) {
        olo = glm::min(olo, p);
        ohi = glm::max(ohi, p);
      }
    }
    lo = glm::min(lo, olo + dlo);
    hi = glm::max(hi, ohi + dhi);

    if (obj.kind == ObjectRecord::Kind::kTriangles) {
      const vec3 nearest = glm::clamp(s.camera.position, olo + dlo, ohi + dhi);
      const float cam_dist = std::max(glm::length(nearest - s.camera.position),
                                      1e-3f * glm::length(ohi - olo));
      obj.time_steps = motion_time_steps(obj, s.shutter_span, cam_dist);
      if (obj.time_steps > 1) {
        obj.step_displacement.resize(obj.time_steps);
        for (int k = 0; k < obj.time_steps; ++k)
          obj.step_displacement[k] = obj.motion.displacement(
              s.shutter_open + s.shutter_span * float(k) / float(obj.time_steps - 1));
      }
    }
  }
  if (input.objects.empty()) lo = hi = vec3(0.f);
  s.bounds_min = lo;
  s.bounds_max = hi;

  // Lights.
  std::vector<Light> lights;
  for (size_t i = 0; i < s.objects.size(); ++i) {
    ObjectRecord& obj = s.objects[i];
    if (is_black(obj.emission) || obj.area <= 0.f) continue;
    obj.light = int(lights.size());
    Light l;
    l.type = Light::Type::kArea;
    l.object = int(i);
    l.value = obj.emission;
    lights.push_back(l);
    s.features.area_lights = true;
  }
  for (const LightDesc& desc : input.lights) {
    Light l;
    if (const auto* p = std::get_if<PointLightDesc>(&desc)) {
      l.type = Light::Type::kPoint;
      l.position = p->position;
      l.value = p->intensity;
      s.features.point_lights = true;
    } else {
      const auto& d = std::get<DirectionalLightDesc>(desc);
      l.type = Light::Type::kDirectional;
      l.direction = glm::normalize(d.direction);
      l.value = d.irradiance;
      s.features.directional_lights = true;
    }
    if (!is_black(l.value)) lights.push_back(l);
  }
  if (s.features.environment) {
    Light l;
    l.type = Light::Type::kEnvironment;
    l.value = s.environment;
    lights.push_back(l);
  }
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-6f);
  s.lights.build(std::move(lights), radius, s.objects);

  // Embree.
  RTCDevice device = embree_device();
  s.rtc_scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(s.rtc_scene, RTC_BUILD_QUALITY_HIGH);
  // Watertight triangle tests; triangle_filter_fn keeps them from re-hitting a ray's own surface.
  // The benchmark's Embree-only baseline traces this same scene, so it pays for both too.
  rtcSetSceneFlags(s.rtc_scene, RTC_SCENE_FLAG_ROBUST);
  static_assert(sizeof(vec3) == 12, "vertex layout");
  std::vector<std::unique_ptr<GeometryData>> geometry_data;
  for (size_t i = 0; i < s.objects.size(); ++i) {
    const ObjectRecord& obj = s.objects[i];
    RTCGeometry geom;
    auto* data = new GeometryData{&s, uint32_t(i)};
    geometry_data.emplace_back(data);
    if (obj.kind == ObjectRecord::Kind::kSphere) {
      geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(geom, 1);
      rtcSetGeometryBoundsFunction(geom, sphere_bounds_fn, nullptr);
      rtcSetGeometryIntersectFunction(geom, sphere_intersect_fn);
      rtcSetGeometryOccludedFunction(geom, sphere_occluded_fn);
    } else {
      geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetGeometryIntersectFilterFunction(geom, triangle_filter_fn);
      rtcSetGeometryOccludedFilterFunction(geom, triangle_filter_fn);
      rtcSetGeometryTimeStepCount(geom, unsigned(obj.time_steps));
      for (int k = 0; k < obj.time_steps; ++k) {
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            geom, RTC_BUFFER_TYPE_VERTEX, unsigned(k), RTC_FORMAT_FLOAT3, sizeof(float) * 3,
            obj.positions.size()));
        if (!v) throw SceneBuildError("Embree could not allocate a vertex buffer: " + take_embree_error());
        const vec3 d = obj.time_steps > 1 ? obj.step_displacement[k] : vec3(0.f);
        for (size_t p = 0; p < obj.positions.size(); ++p) {
          const vec3 q = obj.positions[p] + d;
          v[3 * p] = q.x;
          v[3 * p + 1] = q.y;
          v[3 * p + 2] = q.z;
        }
      }
      auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
          geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(uint32_t) * 3,
          obj.indices.size() / 3));
      if (!idx) throw SceneBuildError("Embree could not allocate an index buffer: " + take_embree_error());
      std::copy(obj.indices.begin(), obj.indices.end(), idx);
    }
    rtcSetGeometryUserData(geom, data);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(s.rtc_scene, geom, unsigned(i));
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(s.rtc_scene);
  const std::string err = take_embree_error();
  if (!err.empty()) throw SceneBuildError(err);
  impl->geometry_data_keepalive = std::move(geometry_data);
  return std::unique_ptr<Scene>(new Scene(std::move(impl)));
}

}  // namespace penumbra
