#pragma once
// Sphere geometry: robust ray intersection, and sampling by solid angle for emitters.
#include "renderer/core/math.h"
#include "renderer/core/ray.h"

namespace penumbra {

struct ShapeSample {
  vec3 p;        // point on the surface
  vec3 p_error;  // its absolute error bound
  vec3 n;        // unit geometric normal (front side)
  float pdf = 0.f;  // solid-angle density seen from the reference point (0 = failed)
};

// Nearest t in (0, t_max) where origin + t*dir (dir unit) meets the sphere, or a negative value.
// Uses the closest-approach form of the discriminant (Haines et al., "Precision Improvements for
// Ray/Sphere Intersection", Ray Tracing Gems, 2019, ch. 7), which stays accurate for spheres that
// are small or far away compared with the ray origin.
float intersect_sphere(const vec3& center, float radius, const vec3& origin, const vec3& dir,
                       float t_max);

// Re-projects a hit onto the sphere and fills position, error bound and normal.
void sphere_hit_geometry(const vec3& center, float radius, const vec3& p_approx, SurfaceHit* hit);

// Samples a point of the sphere visible from `ref` uniformly in solid angle (pbrt-v3 section
// 14.2.2); from inside the sphere, uniformly by area.
ShapeSample sample_sphere(const vec3& center, float radius, const vec3& ref, const vec2& u);
// Solid-angle density of sample_sphere for a point `p` on the sphere seen from `ref`.
float sphere_pdf(const vec3& center, float radius, const vec3& ref, const vec3& p, const vec3& n);

}  // namespace penumbra
