#pragma once
// The one place that maps a shape's input description to its class.
#include <memory>

#include "renderer/scene/scene_input.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

std::unique_ptr<Shape> make_shape(const ShapeDesc& desc, const ShapeContext& ctx);

}  // namespace penumbra
