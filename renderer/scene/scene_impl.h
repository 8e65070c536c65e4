#pragma once
// Renderer-internal view of a built scene: Embree BVH, objects, materials and lights.
// Immutable after Scene::build; every member function is const and thread-safe.
#include <embree3/rtcore.h>

#include <memory>
#include <vector>

#include "renderer/materials/material.h"
#include "renderer/lights/light_sampler.h"
#include "renderer/core/motion.h"
#include "renderer/core/ray.h"
#include "renderer/scene/scene_input.h"
#include "renderer/shapes/sphere_shape.h"

namespace penumbra {

// What a scene contains, decided once at build time so render code can skip what is absent.
struct SceneFeatures {
  bool motion = false;        // any object with nonzero velocity or acceleration
  bool lens = false;          // aperture_radius > 0
  bool transmission = false;  // any dielectric
  bool absorption = false;    // any dielectric with nonzero absorption
  bool area_lights = false;
  bool point_lights = false;
  bool directional_lights = false;
  bool environment = false;
  bool spheres = false;
  bool triangles = false;
};

struct ObjectRecord {
  enum class Kind { kSphere, kTriangles } kind = Kind::kTriangles;
  uint32_t material = 0;
  Spectrum emission{0.f};
  int light = -1;  // index in the light sampler when emissive
  Motion motion;
  // Sphere.
  vec3 center{0.f};
  float radius = 0.f;
  // Triangles (quads are two triangles), world space at t = 0.
  std::vector<vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<vec3> normals;
  bool is_quad = false;
  QuadDesc quad;  // the parallelogram, for uniform sampling of quad emitters
  std::vector<float> triangle_cdf;  // emitters: cumulative triangle areas, normalised
  float area = 0.f;
  // Embree motion: vertex buffers at `time_steps` instants evenly spread over the shutter; the
  // displacement at each step (all vertices share it: motion is rigid).
  int time_steps = 1;
  std::vector<vec3> step_displacement;

  // Displacement at normalised shutter time `time` as Embree interpolates it (triangles) or
  // exactly (spheres).
  vec3 displacement_at(float time, float shutter_open, float shutter_span) const {
    if (motion.is_static()) return vec3(0.f);
    return moving_displacement_at(time, shutter_open, shutter_span);
  }
  vec3 moving_displacement_at(float time, float shutter_open, float shutter_span) const;
};

class SceneImpl;

// User data of one Embree geometry (a sphere's callbacks and a triangle mesh's hit filter read
// the object through it).
struct GeometryData {
  const SceneImpl* scene;
  uint32_t object;
};

class SceneImpl {
 public:
  SceneImpl() = default;
  ~SceneImpl();
  SceneImpl(const SceneImpl&) = delete;
  SceneImpl& operator=(const SceneImpl&) = delete;

  bool intersect(const Ray& ray, SurfaceHit* hit) const;
  bool occluded(const vec3& origin, const vec3& dir, float t_max, float time) const;

  // Scene time (camera units) of a normalised shutter time.
  float scene_time(float time) const { return shutter_open + time * shutter_span; }

  RTCScene rtc_scene = nullptr;
  CameraDesc camera;
  float shutter_open = 0.f, shutter_span = 0.f;
  Spectrum environment{0.f};
  std::vector<Material> materials;
  std::vector<ObjectRecord> objects;  // index = Embree geometry id
  LightSampler lights;
  vec3 bounds_min{0.f}, bounds_max{0.f};
  SceneFeatures features;
  // User data of the Embree geometries (Embree keeps raw pointers to them).
  std::vector<std::unique_ptr<GeometryData>> geometry_data_keepalive;
};

}  // namespace penumbra
