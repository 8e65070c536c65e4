#include "renderer/lights/light_bounds.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

LightBounds LightBounds::merge(const LightBounds& a, const LightBounds& b) {
  if (!(a.phi > 0.f)) return b;
  if (!(b.phi > 0.f)) return a;
  LightBounds out;
  out.bounds = a.bounds;
  out.bounds.extend(b.bounds);
  out.normals = DirectionCone::merge(a.normals, b.normals);
  out.cos_theta_e = std::min(a.cos_theta_e, b.cos_theta_e);
  out.phi = a.phi + b.phi;
  out.two_sided = a.two_sided || b.two_sided;
  return out;
}

}  // namespace penumbra
