#pragma once
// What every light answers for next-event estimation. Lights are chosen by the LightSampler;
// each kind samples itself (an area light through the shape it holds).
//
// Adding a light: a file pair here (a class deriving from Light), its input struct in
// scene/scene_input.h, one line in lights/make_light.cpp, and its tests (docs/architecture.md).
#include <optional>

#include "renderer/core/math.h"
#include "renderer/lights/light_bounds.h"

namespace penumbra {

struct LightSample {
  vec3 wi;                  // unit direction from the reference point towards the light
  float distance = kInfinity;
  Spectrum value{0.f};      // radiance arriving along -wi (point: I/d^2; directional: E)
  float pdf = 0.f;          // solid-angle pdf; for delta lights 1. Excludes the light's choice.
  bool is_delta = false;
  vec3 p{0.f}, p_error{0.f}, n{0.f};  // the point on an area light, for the shadow ray's far end
};

class Light {
 public:
  virtual ~Light() = default;

  // Samples light arriving at `ref` at normalised shutter time `time`; false if none arrives.
  virtual bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const = 0;
  // sample() for n references at once (out[k], its result in ok[k]): the same samples to the bit.
  // A light whose sampling is a chain of dependent table loads runs the chain in stages over all
  // n instead, so that the loads of different samples overlap.
  virtual void sample_many(size_t n, const vec3* refs, const float* times, const vec2* u,
                           LightSample* out, bool* ok) const {
    for (size_t k = 0; k < n; ++k) ok[k] = sample(refs[k], times[k], u[k], &out[k]);
  }
  // An estimate of the emitted power (luminance), from which the light sampler chooses.
  virtual float power(float scene_radius) const = 0;
  // Whether an integrator that weighs light sampling against BSDF sampling by MIS on every
  // lobe (the path integrator) should leave this light to BSDF sampling alone: true where no
  // light sample can beat the BSDF's own. Such a light then gets no next-event estimate and no
  // shadow ray, and a BSDF-sampled ray that reaches it counts with MIS weight 1 (pbrt-v4's
  // "allowIncompletePDF"; Karlik et al. 2019, "MIS compensation").
  virtual bool left_to_bsdf_sampling() const { return false; }
  // Where the light is and which way it shines, for choosing among many lights by the shading
  // point (lights/light_tree.h; phi is left 0: the sampler uses power()); none for a light
  // without a place (an environment, a distant sun), which is chosen by its power alone.
  virtual std::optional<LightBounds> place() const { return std::nullopt; }
};

}  // namespace penumbra
