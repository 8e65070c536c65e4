#pragma once
// A parallelogram origin + s*u + t*v (s, t in [0, 1]), front side along cross(u, v), sampled
// uniformly over (s, t) as a light. A static quad is Embree user geometry with its own ray test
// (shapes/parallelogram.h); a moving one is traced as two triangles (Embree's motion blur of
// vertices, the meshes' exact-t rules of scene/exact_t_check.h).
#include "renderer/shapes/parallelogram.h"
#include "renderer/shapes/triangle_mesh.h"

namespace penumbra {

class Quad final : public TriangleMesh {
 public:
  Quad(const QuadDesc& desc, const ShapeContext& ctx);

  EmbreeGeometry make_geometry(RTCDevice device) const override;
  void hit_geometry(const Ray& ray, float t, uint32_t prim, const vec2& uv,
                    SurfaceHit* hit) const override;
  void surface_derivatives(float time, SurfaceHit* hit) const override;
  bool sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const override;
  vec3 reference_point() const override { return quad_.origin + 0.5f * (quad_.u + quad_.v); }
  // Not Embree triangles while traced as a parallelogram.
  TriangleMesh* triangle_mesh() override { return parallelogram_ ? nullptr : this; }
  std::span<Parallelogram> parallelograms() override {
    return parallelogram_ ? std::span<Parallelogram>(&test_, 1) : std::span<Parallelogram>();
  }

  // Whether it is traced by its own test: static and without a cutout.
  bool parallelogram() const { return parallelogram_; }
  // That test (meaningful only if parallelogram()).
  const Parallelogram& test() const { return test_; }

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
  Parallelogram test_;
  bool parallelogram_;
};

}  // namespace penumbra
