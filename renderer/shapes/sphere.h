#pragma once
// A sphere: Embree user geometry with our own robust intersection (its centre may follow a
// quadratic motion path exactly, which Embree's linear motion of boxes cannot), hit points
// re-projected onto the surface, and sampling by solid angle for emitters.
#include "renderer/scene/scene_input.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

class Sphere final : public Shape {
 public:
  Sphere(const SphereDesc& desc, const ShapeContext& ctx);

  EmbreeGeometry make_geometry(RTCDevice device) const override;
  Bounds3 bounds() const override;
  float area() const override { return area_; }
  void hit_geometry(const Ray& ray, float t, uint32_t prim, const vec2& uv,
                    SurfaceHit* hit) const override;
  void surface_derivatives(float time, SurfaceHit* hit) const override;
  bool sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const override;
  float pdf(const vec3& ref, const vec3& p, const vec3& n, float time) const override;
  vec3 reference_point() const override { return center_; }

  // The centre at normalised shutter time `time` (exact on the motion path).
  vec3 center_at(float time) const {
    return motion_.is_static() ? center_ + vec3(0.f) : center_ + motion_.displacement(time);
  }
  const vec3& center() const { return center_; }  // at time 0
  float radius() const { return radius_; }
  // bounds() padded by the intersection test's rounding error, for Embree's BVH.
  Bounds3 embree_bounds() const;
  const ShapeMotion& motion() const { return motion_; }

 private:
  vec3 center_;  // at time 0
  float radius_;
  float area_;
  ShapeMotion motion_;
  bool need_uv_;    // hits compute their uv (an atan2 and an acos) only if something reads it
  bool sample_uv_;  // the uv of sampled points costs the same: only if asked
};

// Nearest t in (0, t_max) where origin + t*dir (dir unit) meets the sphere, or a negative value.
// Uses the closest-approach form of the discriminant (Haines et al., "Precision Improvements for
// Ray/Sphere Intersection", Ray Tracing Gems, 2019, ch. 7), which stays accurate for spheres that
// are small or far away compared with the ray origin.
// With `take_equal`, a root exactly at t_max counts too (a tie with the ray's current hit that
// this sphere wins: embree/ray_access.h, tie_wins).
float intersect_sphere(const vec3& center, float radius, const vec3& origin, const vec3& dir,
                       float t_max, bool take_equal = false);

// The Embree callbacks of a sphere's user geometry (user data: the Sphere); declared for tests,
// which compare packets of 4, 8 and 16 rays with single rays.
void sphere_intersect_fn(const RTCIntersectFunctionNArguments* args);
void sphere_occluded_fn(const RTCOccludedFunctionNArguments* args);

// Mitsuba 3's sphere mapping of a unit normal: u = phi / 2 pi with phi = atan2(y, x) in
// [0, 2 pi), v = theta / pi from +z (the sphere's frame is unrotated).
vec2 sphere_uv(const vec3& n);
// Re-projects a hit onto the sphere and fills position, error bound and normal.
void sphere_hit_geometry(const vec3& center, float radius, const vec3& p_approx, SurfaceHit* hit);

// Samples a point of the sphere visible from `ref` uniformly in solid angle (pbrt-v3 section
// 14.2.2); from inside the sphere, uniformly by area.
ShapeSample sample_sphere(const vec3& center, float radius, const vec3& ref, const vec2& u);
// Solid-angle density of sample_sphere for a point `p` on the sphere seen from `ref`.
float sphere_pdf(const vec3& center, float radius, const vec3& ref, const vec3& p, const vec3& n);

}  // namespace penumbra
