#pragma once
// Orthonormal shading frame. Local coordinates have the normal on +z.
#include "renderer/core/math.h"

namespace penumbra {

struct Frame {
  vec3 s, t, n;

  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  // Branchless basis from a unit normal: Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
  explicit Frame(const vec3& normal) : n(normal) {
    const float sign = std::copysign(1.f, n.z);
    const float a = -1.f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = vec3(b, sign + n.y * n.y * a, -n.y);
  }
  // Always inline: a few products each, called at every path vertex; GCC otherwise outlines
  // them from the large integrator body (a call per use in the profile).
  [[gnu::always_inline]] vec3 to_local(const vec3& v) const {
    return vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n));
  }
  [[gnu::always_inline]] vec3 to_world(const vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace penumbra
