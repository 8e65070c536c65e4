#pragma once
// Rigid motion of an object: position(t) = position(0) + v*t + a*t^2/2 in scene time units.
#include "renderer/core/math.h"

namespace penumbra {

struct Motion {
  vec3 velocity{0.f};
  vec3 acceleration{0.f};

  bool is_static() const { return velocity == vec3(0.f) && acceleration == vec3(0.f); }
  vec3 displacement(float t) const { return velocity * t + 0.5f * acceleration * (t * t); }
  // Componentwise min and max of the displacement over [t0, t1] (the quadratic's extrema lie at
  // the ends or where v + a*t = 0).
  void displacement_bounds(float t0, float t1, vec3* lo, vec3* hi) const {
    const vec3 a = displacement(t0), b = displacement(t1);
    *lo = glm::min(a, b);
    *hi = glm::max(a, b);
    for (int i = 0; i < 3; ++i) {
      if (acceleration[i] == 0.f) continue;
      const float ts = -velocity[i] / acceleration[i];
      if (ts > t0 && ts < t1) {
        const float e = displacement(ts)[i];
        (*lo)[i] = std::min((*lo)[i], e);
        (*hi)[i] = std::max((*hi)[i], e);
      }
    }
  }
};

}  // namespace penumbra
