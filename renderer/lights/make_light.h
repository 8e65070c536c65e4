#pragma once
// The one place that maps a light's input description to its class (area lights come from
// emitting objects, the environment from SceneInput::environment).
#include <memory>

#include "renderer/lights/light.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

std::unique_ptr<Light> make_light(const LightDesc& desc);

}  // namespace penumbra
