#pragma once
// A triangle mesh: Embree's watertight triangle test with the sign of t settled exactly, hit
// points rebuilt from barycentrics, shading normals and uvs interpolated (without uvs a hit's uv
// is its barycentrics (b1, b2), as Mitsuba 3), uniform sampling by area. A static mesh whose
// triangles pair into parallelograms may be traced as those instead (shapes/parallelogram_pairs.h,
// trace_as_parallelograms); its hits then report the same triangle, barycentrics, uvs and
// normals as a triangle's hit would.
#include <vector>

#include "renderer/scene/scene_input.h"
#include "renderer/shapes/parallelogram_pairs.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

class TriangleMesh : public Shape {
 public:
  TriangleMesh(const MeshDesc& desc, const ShapeContext& ctx);

  EmbreeGeometry make_geometry(RTCDevice device) const override;
  Bounds3 bounds() const override { return bounds_; }
  float area() const override { return area_; }
  void hit_geometry(const Ray& ray, float t, uint32_t prim, const vec2& uv,
                    SurfaceHit* hit) const override;
  void surface_derivatives(float time, SurfaceHit* hit) const override;
  bool sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const override;
  float pdf(const vec3& ref, const vec3& p, const vec3& n, float time) const override;
  vec3 reference_point() const override { return positions_[indices_[0]]; }
  // Around the area-weighted mean of the face normals, as wide as the farthest face normal.
  DirectionCone normal_cone() const override;
  // Not Embree triangles while traced as parallelograms.
  TriangleMesh* triangle_mesh() override { return face_pairs_.shapes.empty() ? this : nullptr; }
  std::span<Parallelogram> parallelograms() override { return face_pairs_.shapes; }

  // Traces the mesh as parallelograms if it is static, has no cutout, is not an emitter (whose
  // samples lie on the triangles), has at most kMaxFacePairs of them and every consecutive
  // triangle pair is one; true if so. The scene build calls it before make_geometry.
  bool trace_as_parallelograms();
  // Boxes, panels and rooms gain (a Cornell box's two boxes: 0.95 of the time; a glass box:
  // 0.80), large meshes do not: Embree's triangle leaves test four at once, a user geometry one
  // primitive per call (a floor of 16 x 16 quads: 1.01 of the time, 64 x 64: 1.08, 200 x 200:
  // 1.15; docs/performance.md, session 28). The scene build also undoes it where the mesh would
  // add the only user geometry beside triangles (scene_builder.cpp, parallelogram_meshes).
  static constexpr size_t kMaxFacePairs = 256;
  // Undoes trace_as_parallelograms (the scene build's own conditions, scene_builder.cpp).
  void trace_as_triangles() { face_pairs_ = FacePairs(); }

  // Whether Embree calls the exact-t test below on every candidate hit (a geometry filter, the
  // default) or the scene checks closest hits after traversal (scene/exact_t_check.h). Set
  // before make_geometry; a mesh with a cutout always filters in traversal (a hole must let
  // the ray through to what lies behind).
  void set_filter_in_traversal(bool on) { filter_in_traversal_ = on; }
  bool filter_in_traversal() const { return filter_in_traversal_ || has_cutout(); }

  // The vertices Embree is given: triangle `prim`'s three at time step `step` (of time_steps();
  // one for a static mesh).
  size_t triangle_count() const { return indices_.size() / 3; }
  int time_steps() const { return time_steps_; }
  void step_triangle(uint32_t prim, int step, vec3 out[3]) const {
    const uint32_t* tri = indices_.data() + size_t(prim) * 3;
    const vec3 d = time_steps_ > 1 ? step_displacement_[size_t(step)] : vec3(0.f);
    for (int k = 0; k < 3; ++k) out[k] = positions_[tri[k]] + d;
  }

  // The displacement of every vertex at normalised shutter time `time`, as Embree interpolates
  // it between its time steps (not the exact quadratic path): hit points must lie on the
  // triangle Embree tested.
  vec3 displacement_at(float time) const {
    return time_steps_ > 1 ? interpolated_displacement(time) : vec3(0.f);
  }
  // True if the ray (origin o, direction d) meets the plane of triangle `prim` at t > 0,
  // decided in double precision (see triangle_mesh.cpp). Inline: Embree calls it on every
  // candidate hit, through the filter function.
  bool ahead_of_ray(uint32_t prim, const vec3& o, const vec3& d, float time) const {
    const uint32_t* tri = indices_.data() + size_t(prim) * 3;
    // The same float vertices hit_geometry rebuilds hit points from.
    vec3 a = positions_[tri[0]], b = positions_[tri[1]], c = positions_[tri[2]];
    if (time_steps_ > 1) {  // moving (static and shutter-less objects have one step)
      const vec3 disp = interpolated_displacement(time);
      a += disp;
      b += disp;
      c += disp;
    }
    const dvec3 p0(a), normal = glm::cross(dvec3(b) - p0, dvec3(c) - p0);
    const double num = glm::dot(p0 - dvec3(o), normal);
    const double den = glm::dot(dvec3(d), normal);
    // Signs compared, not num * den > 0, which could underflow to 0 in a tiny scene.
    return (num > 0.0 && den > 0.0) || (num < 0.0 && den < 0.0);
  }
  // The longest edge of any triangle (motion is rigid: the same at every time).
  float max_edge() const { return max_edge_; }
  // With a cutout: whether the surface exists at barycentrics (b1, b2) of triangle `prim`.
  bool has_cutout() const { return alpha_ != nullptr; }
  bool solid_at(uint32_t prim, float b1, float b2) const;

 protected:
  // For shapes made of triangles that keep their own area and sampling (quads).
  void set_area(float area) { area_ = area; }
  // Whether the mesh moves over the shutter (more than one Embree time step).
  bool moving() const { return time_steps_ > 1; }

 private:
  vec3 interpolated_displacement(float time) const;
  // The uv of barycentric point (b0, b1, b2) of triangle `tri`: interpolated uvs, or (b1, b2).
  vec2 uv_at(const uint32_t* tri, float b0, float b1, float b2) const {
    return uvs_.empty() ? vec2(b1, b2) : b0 * uvs_[tri[0]] + b1 * uvs_[tri[1]] + b2 * uvs_[tri[2]];
  }
  // A hit's uv and shading normal at barycentrics (b0, b1, b2) of triangle `tri`, its geometric
  // normal ng already set.
  void interpolate(const uint32_t* tri, float b0, float b1, float b2, SurfaceHit* hit) const;
  // hit_geometry of a mesh traced as parallelograms: face pair `pair` at (s, t).
  void face_pair_hit(uint32_t pair, const vec2& st, SurfaceHit* hit) const;

  const FloatTexture* alpha_ = nullptr;
  float alpha_factor_ = 1.f, alpha_cutoff_ = 0.5f;
  std::vector<vec3> positions_;  // world space at time 0
  std::vector<uint32_t> indices_;
  std::vector<vec3> normals_;  // empty or one per position
  std::vector<vec2> uvs_;      // empty or one per position
  std::vector<float> triangle_cdf_;  // emitters: cumulative triangle areas, normalised
  // A static mesh's unit geometric normal per triangle, as hit_geometry would compute it (the
  // cross product's square root and division were a third of hit_geometry's time); empty for a
  // moving mesh, whose displaced vertices round differently.
  std::vector<vec3> face_normals_;
  float area_ = 0.f;
  float max_edge_ = 0.f;
  Bounds3 bounds_;
  // Embree motion: vertex buffers at time_steps_ instants evenly spread over the shutter, and
  // the displacement at each (all vertices share it: motion is rigid).
  int time_steps_ = 1;
  std::vector<vec3> step_displacement_;
  bool need_uv_ = false;  // something reads SurfaceHit::uv (ShapeContext::need_uv)
  bool filter_in_traversal_ = true;
  FacePairs face_pairs_;  // empty unless traced as parallelograms
};

}  // namespace penumbra
