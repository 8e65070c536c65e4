#pragma once
// One object of a built scene: its shape, material and, if it emits, its area light.
#include <cstdint>

namespace penumbra {

class Shape;
class AreaLight;

struct SceneObject {
  const Shape* shape = nullptr;
  uint32_t material = 0;                  // index into the scene's materials
  const AreaLight* area_light = nullptr;  // set if the object emits
  int light = -1;                         // the area light's index among the scene's lights
};

}  // namespace penumbra
