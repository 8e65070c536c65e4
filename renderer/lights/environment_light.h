#pragma once
// Light arriving from infinitely far away in every direction: what a ray that leaves the scene
// sees. Rays that escape ask radiance(); next-event estimation samples it.
#include <cstddef>
#include <cstdint>

#include "renderer/lights/light.h"

namespace penumbra {

class EnvironmentLight : public Light {
 public:
  // Radiance arriving along -dir (dir points from the scene towards the sky).
  virtual Spectrum radiance(const vec3& dir) const = 0;
  // Solid-angle density with which sample() picks dir.
  virtual float pdf(const vec3& dir) const = 0;
  // Both at once, as an escaped ray needs them: a map finds the direction's texel once. No pdf
  // is computed where `pdf` is null.
  virtual Spectrum radiance_and_pdf(const vec3& dir, float* pdf) const {
    if (pdf) *pdf = this->pdf(dir);
    return radiance(dir);
  }
  // Whether radiance_and_pdf_many beats one call per direction: a driver that would have to
  // queue the directions first asks for many only then (a constant environment answers in a few
  // instructions, less than the queueing costs).
  virtual bool prefers_many() const { return false; }
  // Builds now whatever the first sample or density would build (a map's sampling table), so
  // that it is counted where the caller wants it (Scene::prepare_sampling). Thread-safe.
  virtual void prepare_sampling() const {}
  // radiance_and_pdf for n directions at once: radiance[k] always, pdf[k] where want_pdf[k] (else
  // left alone); the same values to the bit. A map splits it in stages over all n, so the
  // texel loads of different directions overlap.
  virtual void radiance_and_pdf_many(size_t n, const vec3* dirs, const uint8_t* want_pdf,
                                     Spectrum* radiance, float* pdf) const {
    for (size_t k = 0; k < n; ++k) radiance[k] = radiance_and_pdf(dirs[k], want_pdf[k] ? &pdf[k] : nullptr);
  }
};

// The same radiance from every direction, sampled uniformly over the sphere.
class ConstantEnvironment final : public EnvironmentLight {
 public:
  explicit ConstantEnvironment(const Spectrum& radiance) : radiance_(radiance) {}

  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  // Radiance L over the sphere of directions onto the scene's bounding disc: L 4 pi * pi r^2.
  float power(float scene_radius) const override {
    return luminance(radiance_) * 4.f * kPi * kPi * (scene_radius * scene_radius);
  }
  Spectrum radiance(const vec3&) const override { return radiance_; }
  float pdf(const vec3& dir) const override;
  // The radiance is the same from everywhere, so the integrand at a surface is the BSDF's
  // value times the cosine times visibility: the BSDF's importance sampling follows it (a
  // Lambertian surface's cosine sample has zero variance where the sky is unoccluded), while
  // uniform sphere samples waste half their shadow rays below the surface.
  bool left_to_bsdf_sampling() const override { return true; }

 private:
  Spectrum radiance_;
};

}  // namespace penumbra
