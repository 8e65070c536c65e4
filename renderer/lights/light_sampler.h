#pragma once
// Lights of a scene and the choice among them for next-event estimation.
#include <vector>

#include "renderer/core/math.h"
#include "renderer/shapes/sphere_shape.h"

namespace penumbra {

class SceneImpl;
struct ObjectRecord;

struct Light {
  enum class Type { kArea, kPoint, kDirectional, kEnvironment } type = Type::kArea;
  int object = -1;        // kArea: the emitting object
  vec3 position{0.f};     // kPoint
  vec3 direction{0.f};    // kDirectional: the direction light travels (unit)
  Spectrum value{0.f};    // emission radiance, intensity, irradiance or environment radiance
};

struct LightSample {
  vec3 wi;                 // unit direction from the reference point towards the light
  float distance = kInfinity;
  Spectrum value{0.f};     // radiance arriving along -wi (for point: I/d^2; directional: E)
  float pdf = 0.f;         // solid-angle pdf including the light choice; for delta lights the choice only
  bool is_delta = false;
  vec3 p{0.f}, p_error{0.f}, n{0.f};  // the point on an area light, for the shadow ray's far end
};

class LightSampler {
 public:
  // Builds the selection distribution: half proportional to each light's power, half uniform,
  // so a dim but important light is never starved.
  void build(std::vector<Light> lights, float scene_radius,
             const std::vector<ObjectRecord>& objects);

  bool empty() const { return lights_.empty(); }
  const std::vector<Light>& lights() const { return lights_; }
  int environment_light() const { return environment_; }
  float selection_pmf(int light) const { return pmf_[light]; }

  // Samples a light and a point on it as seen from `ref` at normalised time `time`.
  bool sample(const SceneImpl& scene, const vec3& ref, float time, float u_select, const vec2& u,
              LightSample* out) const;
  // pdf (with selection) that sample() yields the point p (normal n) of area light `light` from ref.
  float area_pdf(const SceneImpl& scene, int light, const vec3& ref, const vec3& p, const vec3& n,
                 float time) const;
  float environment_pdf() const;

 private:
  std::vector<Light> lights_;
  std::vector<float> pmf_, cdf_;
  int environment_ = -1;
};

}  // namespace penumbra
