#include "renderer/lights/area_light.h"

namespace penumbra {

bool AreaLight::sample(const vec3& ref, float time, const vec2& u, LightSample* out) const {
  ShapeSample ss;
  if (!shape_.sample(ref, time, u, &ss)) return false;
  if (!(ss.pdf > 0.f) || !std::isfinite(ss.pdf)) return false;
  const vec3 d = ss.p - ref;
  const float dist = glm::length(d);
  if (!(dist > 0.f)) return false;
  out->wi = d / dist;
  out->distance = dist;
  // Emission leaves the front side only.
  if (glm::dot(ss.n, out->wi) >= 0.f) return false;
  out->value = radiance(TextureQuery{ss.p, ss.uv, time});
  out->pdf = ss.pdf;
  out->is_delta = false;
  out->p = ss.p;
  out->p_error = ss.p_error;
  out->n = ss.n;
  return true;
}

// A Lambertian emitter of radiance L and area A emits pi L A; a textured one, its mean radiance
// (the texture's mean over the image, which is its mean over the surface when the uv map
// preserves area, and close enough to choose lights by otherwise).
float AreaLight::power(float) const {
  const Spectrum mean = texture_ ? radiance_ * glm::max(texture_->mean(), Spectrum(0.f)) : radiance_;
  return luminance(mean) * shape_.area() * kPi;
}

}  // namespace penumbra
