#include "renderer/shapes/make_shape.h"

#include "renderer/shapes/quad.h"
#include "renderer/shapes/sphere.h"
#include "renderer/shapes/triangle_mesh.h"

namespace penumbra {
namespace {

// One line per shape kind: its input struct and its class.
std::unique_ptr<Shape> make(const SphereDesc& d, const ShapeContext& c) { return std::make_unique<Sphere>(d, c); }
std::unique_ptr<Shape> make(const QuadDesc& d, const ShapeContext& c) { return std::make_unique<Quad>(d, c); }
std::unique_ptr<Shape> make(const MeshDesc& d, const ShapeContext& c) { return std::make_unique<TriangleMesh>(d, c); }

}  // namespace

std::unique_ptr<Shape> make_shape(const ShapeDesc& desc, const ShapeContext& ctx) {
  return std::visit([&](const auto& d) { return make(d, ctx); }, desc);
}

}  // namespace penumbra
