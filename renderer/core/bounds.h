#pragma once
// Axis-aligned bounding box.
#include "renderer/core/math.h"

namespace penumbra {

struct Bounds3 {
  vec3 lo{kInfinity};
  vec3 hi{-kInfinity};

  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  void extend(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Bounds3& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
};

}  // namespace penumbra
