#pragma once
// A diffuse emitter: radiance leaving the front side of the shape it holds, constant or
// textured over the shape's uv (the constant times the texture, as a material's parameters).
#include <memory>

#include "renderer/lights/light.h"
#include "renderer/shapes/shape.h"
#include "renderer/textures/texture.h"

namespace penumbra {

class AreaLight final : public Light {
 public:
  // `texture` (may be null) multiplies `radiance`; negative texels emit nothing.
  AreaLight(const Shape& shape, const Spectrum& radiance,
            std::unique_ptr<const SpectrumTexture> texture = nullptr)
      : shape_(shape), radiance_(radiance), texture_(std::move(texture)) {}

  // Points are sampled uniformly by the shape (by area or solid angle), not by the texture:
  // unbiased for any texture, only noisier for a very uneven one.
  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  float power(float scene_radius) const override;
  // The shape's box over the shutter and its normals' cone; light leaves each point into the
  // hemisphere of its normal.
  std::optional<LightBounds> place() const override {
    LightBounds b;
    b.bounds = shape_.bounds();
    b.normals = shape_.normal_cone();
    b.cos_theta_e = 0.f;
    return b;
  }

  // Radiance leaving the front side at a point of the surface.
  Spectrum radiance(const TextureQuery& q) const {
    return texture_ ? radiance_ * glm::max(texture_->eval(q), Spectrum(0.f)) : radiance_;
  }
  // Solid-angle density with which sample() reaches point p (normal n) from ref.
  float pdf(const vec3& ref, const vec3& p, const vec3& n, float time) const {
    return shape_.pdf(ref, p, n, time);
  }
  const Shape& shape() const { return shape_; }
  bool textured() const { return texture_ != nullptr; }
  // What radiance() multiplies: the constant, and the texture (null when untextured).
  const Spectrum& radiance_factor() const { return radiance_; }
  const SpectrumTexture* texture() const { return texture_.get(); }

 private:
  const Shape& shape_;
  Spectrum radiance_;
  std::unique_ptr<const SpectrumTexture> texture_;
};

}  // namespace penumbra
