// Scene::build as a sequence of named steps. Everything a step creates is owned by the Scene
// under construction or by an RAII handle, so a step that throws leaks nothing.
#include <embree3/rtcore.h>

#include <utility>
#include <vector>

#include "renderer/embree/device.h"
#include "renderer/embree/handles.h"
#include "renderer/lights/area_light.h"
#include "renderer/lights/environment_map.h"
#include "renderer/lights/make_light.h"
#include "renderer/materials/coating_tables.h"
#include "renderer/scene/coplanar_parallelograms.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/make_shape.h"
#include "renderer/shapes/quad.h"
#include "renderer/shapes/triangle_mesh.h"
#include "renderer/textures/image_texture.h"
#include "renderer/textures/texture_image_cache.h"

namespace penumbra {

namespace {

// A texture's image that cannot be read now (api/ checked its header; the file may have
// changed since, or its pixels may be corrupt) fails the build like any other resource.
template <typename F>
auto with_image_errors(F&& f) {
  try {
    return f();
  } catch (const ImageIoError& e) {
    throw SceneBuildError(std::string("texture ") + e.what());
  }
}

}  // namespace

class SceneBuilder {
 public:
  SceneBuilder(const SceneInput& input, Scene& scene) : in_(input), s_(scene) {}

  void camera_and_shutter() {
    s_.camera_ = in_.camera;
    shutter_open_ = in_.camera.shutter_open;
    shutter_span_ = std::max(0.f, in_.camera.shutter_close - in_.camera.shutter_open);
    s_.features_.lens = in_.camera.aperture_radius > 0.f;
  }

  // Materials answer for themselves what the integrator must be compiled for. Their coating
  // tables and texture images are shared through caches the scene keeps.
  void materials() {
    s_.coatings_ = std::make_unique<CoatingTableCache>();
    s_.texture_images_ = std::make_unique<TextureImageCache>(in_.texture_limits);
    s_.materials_.reserve(in_.materials.size());
    for (const MaterialParams& params : in_.materials) {
      const Material& m = *with_image_errors(
          [&] { return &s_.materials_.emplace_back(params, s_.coatings_.get(), s_.texture_images_.get()); });
      if (m.has_transmission()) s_.features_.transmission = true;
      if (m.has_absorption()) s_.features_.absorption = true;
      // A textured parameter or a normal map reads the hit's uv (spheres compute it only then).
      if (m.varies()) s_.features_.textures = true;
    }
    // Textured emission is looked up at the hit's uv too.
    for (const ObjectDesc& desc : in_.objects)
      if (desc.emission_texture) s_.features_.textures = true;
  }

  void shapes() {
    s_.shapes_.reserve(in_.objects.size());
    s_.objects_.resize(in_.objects.size());
    for (size_t i = 0; i < in_.objects.size(); ++i) {
      const ObjectDesc& desc = in_.objects[i];
      ShapeContext ctx;
      ctx.motion = ShapeMotion{Motion{desc.velocity, desc.acceleration}, shutter_open_, shutter_span_};
      // Without a shutter interval there is no blur: bake the place at the shutter time in.
      if (shutter_span_ <= 0.f) {
        ctx.offset = ctx.motion.motion.displacement(shutter_open_);
        ctx.motion.motion = Motion{};
      }
      if (!ctx.motion.is_static()) s_.features_.motion = true;
      ctx.camera_position = in_.camera.position;
      ctx.emissive = !is_black(desc.emission);
      ctx.need_uv = s_.features_.textures;
      ctx.sample_uv = ctx.emissive && desc.emission_texture.has_value();
      if (desc.alpha_texture) {
        s_.alpha_textures_.push_back(with_image_errors(
            [&] { return make_float_texture(*desc.alpha_texture, *s_.texture_images_); }));
        ctx.alpha = s_.alpha_textures_.back().get();
        ctx.alpha_factor = desc.alpha_factor;
        ctx.alpha_cutoff = desc.alpha_cutoff;
      }
      s_.shapes_.push_back(make_shape(desc.shape, ctx));
      s_.objects_[i].shape = s_.shapes_.back().get();
      s_.objects_[i].material = desc.material;
    }
  }

  // Copies of meshes (shapes/instance.h). Only a mesh that does not emit can be copied: an
  // area light samples its own shape, and a copy has none (the api reports this on the field).
  void instances() {
    size_t copies = 0;
    for (const InstancesDesc& desc : in_.instances) copies += desc.transforms.size();
    s_.instances_.reserve(copies);
    for (const InstancesDesc& desc : in_.instances) {
      if (desc.object >= s_.objects_.size())
        throw SceneBuildError("instances of object " + std::to_string(desc.object) +
                              ": no such object");
      const Shape& shape = *s_.objects_[desc.object].shape;
      if (!std::holds_alternative<MeshDesc>(in_.objects[desc.object].shape) ||
          !is_black(in_.objects[desc.object].emission))
        throw SceneBuildError("instances of object " + std::to_string(desc.object) +
                              ": only a mesh that does not emit can be instanced");
      for (const InstanceTransform& t : desc.transforms)
        s_.instances_.emplace_back(shape, desc.object, t);
    }
  }

  void bounds() {
    Bounds3 b;
    for (const auto& shape : s_.shapes_) b.extend(shape->bounds());
    for (const Instance& copy : s_.instances_) b.extend(copy.bounds());
    if (s_.shapes_.empty()) b = Bounds3{vec3(0.f), vec3(0.f)};
    s_.bounds_ = b;
  }

  // Area lights (in object order), then the scene's lights, then the environment: the order
  // fixes light indices and so the sampler's choices.
  void lights() {
    for (size_t i = 0; i < in_.objects.size(); ++i) {
      const Shape& shape = *s_.shapes_[i];
      if (is_black(in_.objects[i].emission) || shape.area() <= 0.f) continue;
      const auto& texture = in_.objects[i].emission_texture;
      auto light = std::make_unique<AreaLight>(
          shape, in_.objects[i].emission,
          texture ? with_image_errors([&] { return make_spectrum_texture(*texture, *s_.texture_images_); })
                  : nullptr);
      s_.objects_[i].area_light = light.get();
      s_.objects_[i].light = int(s_.lights_.size());
      s_.lights_.push_back(std::move(light));
    }
    for (const LightDesc& desc : in_.lights)
      if (auto light = make_light(desc)) s_.lights_.push_back(std::move(light));
    if (in_.environment_map) {
      // A map that emits nothing is left out, as a black constant environment is.
      auto map = std::make_unique<EnvironmentMap>(*in_.environment_map);
      if (!map->is_black()) {
        s_.mis_environment_ = map->compensated();
        add_environment(std::move(map));
      }
    } else if (!is_black(in_.environment)) {
      add_environment(std::make_unique<ConstantEnvironment>(in_.environment));
    }
    s_.features_.lights = !s_.lights_.empty();
    const float radius = std::max(0.5f * glm::length(s_.bounds_.hi - s_.bounds_.lo), 1e-6f);
    std::vector<float> powers;
    std::vector<bool> mis_sampled;
    std::vector<std::optional<LightBounds>> places;
    for (int l = 0; l < s_.light_count(); ++l) {
      powers.push_back(s_.light(l).power(radius));
      mis_sampled.push_back(!s_.mis_light(l).left_to_bsdf_sampling());
      places.push_back(s_.light(l).place());
    }
    s_.light_sampler_ = LightSampler(powers, std::vector<bool>(powers.size(), true), places);
    s_.mis_light_sampler_ = LightSampler(powers, mis_sampled, places);
    s_.features_.mis_lights = !s_.mis_light_sampler_.empty();
  }

  void add_environment(std::unique_ptr<EnvironmentLight> env) {
    s_.environment_ = env.get();
    s_.environment_light_ = int(s_.lights_.size());
    s_.lights_.push_back(std::move(env));
    s_.features_.environment = true;
  }

  // One child scene per instanced mesh, holding the mesh's own geometry; then one Embree
  // instance per copy, with ids after the objects'.
  void attach_instances(RTCDevice device, RTCScene scene, RTCSceneFlags flags,
                        const std::vector<EmbreeGeometry>& geometries, EmbreeErrorScope& errors) {
    std::vector<RTCScene> child_of(s_.objects_.size(), nullptr);
    for (size_t k = 0; k < s_.instances_.size(); ++k) {
      const Instance& copy = s_.instances_[k];
      RTCScene& child = child_of[copy.object()];
      if (!child) {
        EmbreeScene made = make_instanced_scene(device, geometries[copy.object()].get(), flags);
        if (!made) throw SceneBuildError("Embree could not create a scene: " + errors.first_error());
        child = made.get();
        s_.instanced_scenes_.push_back(std::move(made));
      }
      const EmbreeGeometry geom = copy.make_geometry(device, child);
      if (!geom)
        throw SceneBuildError("Embree could not create instance " + std::to_string(k) + ": " +
                              errors.first_error());
      rtcAttachGeometryByID(scene, geom.get(), unsigned(s_.objects_.size() + k));
    }
  }

  // Static meshes made of quads are traced as parallelograms (shapes/parallelogram_pairs.h),
  // copied ones too (the test runs in the callback on the ray Embree maps into the copy, so it
  // needs no check after traversal), unless holding a face twice (coincident faces tie at every
  // point; triangles have the rule below for them). Embree keeps one BVH per kind of primitive
  // and every ray traverses each, so converting pays only where the scene already has user
  // geometry (spheres, static quads) or no triangles stay: a glTF scene of triangles whose
  // floor, one quad, became the only user primitive took 1.03 of the time, 0.98 with a sphere
  // beside it (docs/performance.md, levers, session 29).
  void parallelogram_meshes() {
    bool user_geometry = false, triangles_stay = false;
    std::vector<TriangleMesh*> converted;
    for (auto& shape : s_.shapes_) {
      TriangleMesh* mesh = shape->triangle_mesh();
      if (!mesh) {
        user_geometry = true;  // a sphere or a quad traced by its own test
        continue;
      }
      if (mesh->trace_as_parallelograms() && !has_coincident_triangles({mesh})) {
        converted.push_back(mesh);
        continue;
      }
      mesh->trace_as_triangles();
      triangles_stay = true;
    }
    if (triangles_stay && !user_geometry)
      for (TriangleMesh* mesh : converted) mesh->trace_as_triangles();
  }

  // Where each mesh's exact-t test runs (scene/exact_t_check.h): a mesh without a cutout and
  // without copies is checked after traversal, unless two triangles of the scene coincide:
  // Embree's filter-free kernels break their exact-t ties differently in packets and in single
  // rays, so then every mesh keeps its geometry filter, whose kernels agree. Copies keep it
  // because Embree hands the filter the ray mapped by its own float inverse, which a check
  // after the fact could not reproduce bit for bit.
  void exact_t_check() {
    std::vector<bool> copied(s_.objects_.size(), false);
    for (const Instance& copy : s_.instances_) copied[copy.object()] = true;
    std::vector<const TriangleMesh*> meshes, plain(s_.objects_.size(), nullptr);
    bool any_plain = false;
    for (size_t i = 0; i < s_.shapes_.size(); ++i) {
      const TriangleMesh* mesh = s_.shapes_[i]->triangle_mesh();
      if (!mesh) continue;
      meshes.push_back(mesh);
      if (!mesh->has_cutout() && !copied[i]) {
        plain[i] = mesh;
        any_plain = true;
      }
    }
    if (!any_plain || has_coincident_triangles(meshes)) return;  // every mesh filters
    for (size_t i = 0; i < plain.size(); ++i)
      if (plain[i]) s_.shapes_[i]->triangle_mesh()->set_filter_in_traversal(false);
    s_.exact_t_ = ExactTCheck(std::move(plain));
  }

  // Parallelograms that can tie with another shape's in their plane get thick boxes
  // (scene/coplanar_parallelograms.h).
  void thicken_coplanar() {
    std::vector<PlacedParallelogram> all;
    for (size_t i = 0; i < s_.shapes_.size(); ++i)
      for (Parallelogram& q : s_.shapes_[i]->parallelograms()) all.push_back({&q, uint32_t(i)});
    thicken_coplanar_parallelograms(all);
  }

  void embree_scene() {
    parallelogram_meshes();
    exact_t_check();
    thicken_coplanar();
    RTCDevice device = embree_device();
    EmbreeErrorScope errors;
    EmbreeScene scene(rtcNewScene(device));
    if (!scene) throw SceneBuildError("Embree could not create a scene: " + errors.first_error());
    rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_HIGH);
    // Watertight triangle tests (shapes/triangle_mesh.cpp rejects their re-hits of the surface a
    // ray leaves, in traversal or after it) and, when meshes are checked after traversal, the
    // context filter that retraces and occlusion queries run. The Embree-only benchmark traces
    // this same scene, so it pays for them too.
    const RTCSceneFlags flags = s_.exact_t_.enabled()
        ? RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION)
        : RTC_SCENE_FLAG_ROBUST;
    rtcSetSceneFlags(scene.get(), flags);
    std::vector<EmbreeGeometry> geometries(s_.shapes_.size());  // kept for the instances
    for (size_t i = 0; i < s_.shapes_.size(); ++i) {
      geometries[i] = s_.shapes_[i]->make_geometry(device);
      if (!geometries[i])
        throw SceneBuildError("Embree could not create the geometry of object " + std::to_string(i) +
                              ": " + errors.first_error());
      rtcAttachGeometryByID(scene.get(), geometries[i].get(), unsigned(i));
    }
    attach_instances(device, scene.get(), flags, geometries, errors);
    rtcCommitScene(scene.get());
    const std::string error = errors.first_error();
    if (!error.empty()) throw SceneBuildError(error);
    s_.rtc_scene_ = scene.release();
  }

 private:
  const SceneInput& in_;
  Scene& s_;
  float shutter_open_ = 0.f, shutter_span_ = 0.f;
};

std::unique_ptr<Scene> Scene::build(const SceneInput& input) {
  std::unique_ptr<Scene> scene(new Scene());
  SceneBuilder b(input, *scene);
  b.camera_and_shutter();
  b.materials();
  b.shapes();
  b.instances();
  b.bounds();
  b.lights();
  b.embree_scene();
  return scene;
}

}  // namespace penumbra
