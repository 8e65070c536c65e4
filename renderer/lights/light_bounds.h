#pragma once
// Where a light (or a group of lights) is and which way it shines: a box around its points, the
// cone of its surface normals and a bound of its radiant intensity, for choosing among many lights by where the
// shading point is (lights/light_tree.h). Conty Estevez and Kulla 2018; pbrt-v4 section 12.6.3.
#include "renderer/core/bounds.h"
#include "renderer/core/direction_cone.h"
#include "renderer/core/math.h"

namespace penumbra {

// What a light (or a node's lights together) emits where: its points lie in `bounds`, its
// surface normals within `normals`, light leaves each point within `cos_theta_e` of the normal
// (cos(pi/2) = 0 for a Lambertian emitter), `phi` a bound of its radiant intensity (luminance
// per steradian, as the light sampler sets it from the power) or, for a node, its lights' sum.
// A point light has a point box, the whole sphere of normals and cos_theta_e = 0.
struct LightBounds {
  Bounds3 bounds;
  DirectionCone normals;
  float cos_theta_e = 0.f;
  float phi = 0.f;
  bool two_sided = false;

  static LightBounds merge(const LightBounds& a, const LightBounds& b);
};

}  // namespace penumbra
