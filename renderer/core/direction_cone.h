#pragma once
// A cone of directions around an axis: the normals of a surface, or the directions a group of
// lights emits into (lights/light_bounds.h).
#include "renderer/core/math.h"

namespace penumbra {

// The cone of directions {w : angle(w, axis) <= theta} with cos_theta = cos(theta); cos_theta
// = -1 is the whole sphere (any axis).
struct DirectionCone {
  vec3 axis{0.f, 0.f, 1.f};
  float cos_theta = -1.f;

  static DirectionCone whole_sphere() { return {}; }
  // The smallest cone holding both (pbrt-v4's Union(DirectionCone, DirectionCone)).
  static DirectionCone merge(const DirectionCone& a, const DirectionCone& b);
};

}  // namespace penumbra
