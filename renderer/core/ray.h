#pragma once
// Rays, surface hits, and the spawn-ray offset that keeps a new ray off the surface it left.
#include <cstring>
#include <limits>

#include "renderer/core/math.h"

namespace penumbra {

struct Ray {
  vec3 origin;
  vec3 direction;  // unit length
  float time = 0.f;  // normalised shutter time in [0,1]
  float t_max = kInfinity;
};

// gamma(n) = n*eps / (1 - n*eps), the rounding-error bound of n chained floating-point
// operations (Higham 2002; pbrt-v4 section 6.8.1).
inline constexpr float gamma_bound(int n) {
  constexpr float eps = std::numeric_limits<float>::epsilon() * 0.5f;
  return (float(n) * eps) / (1.f - float(n) * eps);
}

// Moves a point whose absolute floating-point error is bounded by `error` (per component) off
// the surface with geometric normal `n`, to the side `w` leaves towards, far enough that the
// rounding error cannot put it on the other side, then one ulp further (pbrt-v4 section 6.8.6).
// Adjacent floats by stepping the bit pattern (pbrt-v4 NextFloatUp / NextFloatDown); std::nextafter
// is a library call with edge-case handling that showed up in profiles.
inline float next_float_up(float v) {
  if (std::isinf(v) && v > 0.f) return v;
  if (v == -0.f) v = 0.f;
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  bits = v >= 0.f ? bits + 1 : bits - 1;
  std::memcpy(&v, &bits, sizeof bits);
  return v;
}
inline float next_float_down(float v) {
  if (std::isinf(v) && v < 0.f) return v;
  if (v == 0.f) v = -0.f;
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  bits = v > 0.f ? bits - 1 : bits + 1;
  std::memcpy(&v, &bits, sizeof bits);
  return v;
}

inline vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n, const vec3& w) {
  const float d = glm::dot(abs_components(n), error);
  vec3 offset = d * n;
  if (glm::dot(w, n) < 0.f) offset = -offset;
  vec3 po = p + offset;
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.f) po[i] = next_float_up(po[i]);
    else if (offset[i] < 0.f) po[i] = next_float_down(po[i]);
  }
  return po;
}

// Fraction of a shadow ray's length left out at the far end, as pbrt's ShadowEpsilon: the light
// point is itself offset from its surface, so this only absorbs the rounding of t.
inline constexpr float kShadowEpsilon = 1e-4f;

struct SurfaceHit {
  float t = 0.f;
  vec3 p;          // recomputed from the primitive (not o + t*d)
  vec3 p_error;    // absolute error bound of p per component
  vec3 ng;         // unit geometric normal, the shape's front side (u x v, CCW, outside)
  vec3 ns;         // unit shading normal, same hemisphere as ng
  vec2 uv{0.f};    // surface coordinates for textures (each shape documents its mapping)
  // dp/du and dp/dv of the uv parametrisation, for a tangent frame (normal maps). Not set by
  // intersect(): Shape::surface_derivatives fills them when a material needs them.
  vec3 dpdu{0.f}, dpdv{0.f};
  uint32_t object = 0;
  uint32_t primitive = 0;
  // The copy hit (Scene::instance), or kNotACopy: a copy's hit reports its mesh's object.
  static constexpr uint32_t kNotACopy = ~0u;
  uint32_t instance = kNotACopy;
};

}  // namespace penumbra
