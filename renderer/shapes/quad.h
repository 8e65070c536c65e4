#pragma once
// A parallelogram origin + s*u + t*v (s, t in [0, 1]), front side along cross(u, v): traced as
// two triangles, sampled uniformly over (s, t) as a light.
#include "renderer/shapes/triangle_mesh.h"

namespace penumbra {

class Quad final : public TriangleMesh {
 public:
  Quad(const QuadDesc& desc, const ShapeContext& ctx);

  bool sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const override;
  vec3 reference_point() const override { return quad_.origin + 0.5f * (quad_.u + quad_.v); }

  // What sample() reads, for the wavefront driver's light kernels (render/light_kernels.h).
  const QuadDesc& desc() const { return quad_; }
  const vec3& normal() const { return normal_; }
  using TriangleMesh::moving;

 private:
  QuadDesc quad_;  // origin moved by the context's offset
  // Its unit normal, computed once: light sampling asks for it on every shadow ray, and the
  // cross product, square root and division were a visible share of a Cornell box's samples
  // (docs/performance.md).
  vec3 normal_;
};

}  // namespace penumbra
