#pragma once
// The render scene: built once from a SceneInput (shapes, materials, lights, Embree BVH), then
// immutable and shared const by every render thread. Integrators see it only through these
// const queries.
#include <memory>
#include <vector>

#include "renderer/core/bounds.h"
#include "renderer/core/errors.h"
#include "renderer/core/ray.h"
#include "renderer/lights/environment_light.h"
#include "renderer/lights/light_sampler.h"
#include "renderer/materials/material.h"
#include "renderer/scene/exact_t_check.h"
#include "renderer/scene/scene_features.h"
#include "renderer/scene/scene_input.h"
#include "renderer/scene/scene_object.h"
#include "renderer/shapes/instance.h"

struct RTCSceneTy;  // Embree's scene handle

namespace penumbra {

class Shape;
class Light;
class CoatingTableCache;
class TextureImageCache;

class Scene {
 public:
  // Throws SceneBuildError (e.g. an Embree failure). Input is assumed validated.
  static std::unique_ptr<Scene> build(const SceneInput& input);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // Nearest surface along the ray (t in (0, ray.t_max)), with its geometry rebuilt by its shape.
  bool intersect(const Ray& ray, SurfaceHit* hit) const;
  // Fills hit->dpdu and dpdv (Shape::surface_derivatives) of a hit intersect() returned, on an
  // object or on a copy (shapes/instance.h).
  void surface_derivatives(float time, SurfaceHit* hit) const;
  // Whether anything blocks origin + t*dir for t in (0, t_max) at normalised time `time`.
  bool occluded(const vec3& origin, const vec3& dir, float t_max, float time) const;

  // The same queries for up to kPacketSize rays at once, traced as one Embree packet
  // (rtcIntersect16 / rtcOccluded16): found[i] and hits[i] (occluded[i]) are what intersect()
  // (occluded()) gives for rays[i]. `coherent`: the rays start close together and point alike
  // (camera rays), which lets Embree trace them as a bundle.
  static constexpr int kPacketSize = 16;
  void intersect_packet(const Ray* rays, int count, bool coherent, SurfaceHit* hits,
                        bool* found) const;
  void occluded_packet(const Ray* rays, int count, bool* occluded) const;

  const CameraDesc& camera() const { return camera_; }
  const SceneFeatures& features() const { return features_; }
  // World bounds of every object over the shutter (empty scene: a point at the origin).
  const Bounds3& bounds() const { return bounds_; }

  size_t object_count() const { return objects_.size(); }
  // Placed copies of mesh objects (SceneInput::instances, flattened); a hit on one reports its
  // mesh's object index.
  size_t instance_count() const { return instances_.size(); }
  const Instance& instance(size_t index) const { return instances_[index]; }
  const SceneObject& object(uint32_t id) const { return objects_[id]; }
  const Material& material(uint32_t index) const { return materials_[index]; }

  // The choice of a light for next-event estimation over every light: for integrators that see
  // some lobes' direct light only through light sampling (the distributed integrator).
  const LightSampler& light_sampler() const { return light_sampler_; }
  // The same over the lights the path integrator samples, which weighs light against BSDF
  // sampling by MIS everywhere: all but those left to BSDF sampling
  // (Light::left_to_bsdf_sampling; same indices, the others with pmf 0).
  const LightSampler& mis_light_sampler() const { return mis_light_sampler_; }
  const Light& light(int index) const { return *lights_[size_t(index)]; }
  int light_count() const { return int(lights_.size()); }
  // The environment (nullptr if rays that escape see black) and its index among the lights.
  const EnvironmentLight* environment() const { return environment_; }
  int environment_light() const { return environment_light_; }
  // The light `index` and the environment as the path integrator samples them and weighs their
  // MIS: light(index) and environment(), except an environment map, which it samples where it
  // is brighter than its mean (EnvironmentMap::compensated, MIS compensation).
  const Light& mis_light(int index) const {
    return index == environment_light_ && mis_environment_ ? *mis_environment_ : *lights_[size_t(index)];
  }
  const EnvironmentLight* mis_environment() const {
    return mis_environment_ ? mis_environment_.get() : environment_;
  }
  // Builds the tables a render with `integrator` samples and that are otherwise built by its
  // first sample: the sampling table of the environment map, or of its compensated twin (each
  // as large as the image; a render needs one of them). render() calls it; a caller that times
  // the scene's build calls it right after Scene::build, so the table counts as build time.
  void prepare_sampling(IntegratorKind integrator) const {
    const EnvironmentLight* env = integrator == IntegratorKind::kDistributed ? environment_ : mis_environment();
    if (env) env->prepare_sampling();
  }

  // The Embree scene, for the Embree-only benchmark (render/embree_baseline.cpp). Rays that
  // leave a surface must be traced with exact_t_check().context(...) to skip re-hits of it.
  RTCSceneTy* embree_scene() const { return rtc_scene_; }
  // Where the exact-t test of triangle hits runs (scene/exact_t_check.h): enabled() if plain
  // meshes are checked after traversal, off if every mesh filters in traversal.
  const ExactTCheck& exact_t_check() const { return exact_t_; }

 private:
  // The hit record of Embree's answer: which object or copy, and its geometry from the shape.
  void complete_hit(const Ray& ray, float t, uint32_t geom_id, uint32_t inst_id, uint32_t prim_id,
                    vec2 uv, SurfaceHit* hit) const;

  friend class SceneBuilder;
  Scene() = default;

  CameraDesc camera_;
  SceneFeatures features_;
  Bounds3 bounds_;
  // What materials and emitters point into: the plastics' coating tables and the decoded
  // texture images, each computed or decoded once per scene.
  std::unique_ptr<CoatingTableCache> coatings_;
  std::unique_ptr<TextureImageCache> texture_images_;
  std::vector<Material> materials_;
  std::vector<std::unique_ptr<FloatTexture>> alpha_textures_;  // cutouts, pointed to by shapes
  std::vector<std::unique_ptr<Shape>> shapes_;
  std::vector<SceneObject> objects_;  // index = Embree geometry id
  // Embree geometry id = objects_.size() + index. The child scenes they instance (one per
  // instanced mesh) are owned here and released after rtc_scene_.
  std::vector<Instance> instances_;
  std::vector<EmbreeScene> instanced_scenes_;
  std::vector<std::unique_ptr<Light>> lights_;
  LightSampler light_sampler_, mis_light_sampler_;
  const EnvironmentLight* environment_ = nullptr;
  int environment_light_ = -1;
  std::unique_ptr<EnvironmentLight> mis_environment_;  // nullptr: environment_ itself
  ExactTCheck exact_t_;
  RTCSceneTy* rtc_scene_ = nullptr;  // owned; released before the shapes it points into
};

}  // namespace penumbra
