#pragma once
// A diffuse emitter: constant radiance leaving the front side of the shape it holds.
#include "renderer/lights/light.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

class AreaLight final : public Light {
 public:
  AreaLight(const Shape& shape, const Spectrum& radiance) : shape_(shape), radiance_(radiance) {}

  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  float power(float scene_radius) const override;

  // Radiance leaving the front side.
  const Spectrum& radiance() const { return radiance_; }
  // Solid-angle density with which sample() reaches point p (normal n) from ref.
  float pdf(const vec3& ref, const vec3& p, const vec3& n, float time) const {
    return shape_.pdf(ref, p, n, time);
  }
  const Shape& shape() const { return shape_; }

 private:
  const Shape& shape_;
  Spectrum radiance_;
};

}  // namespace penumbra
