#pragma once
// What every shape answers, in one place per kind (as pbrt-v4's shapes.h and Mitsuba 3's
// src/shapes/*.cpp): its Embree geometry, its bounds and area, the reconstruction of a hit point
// with its floating-point error bound, and sampling of points for area lights.
//
// Adding a shape: a file pair here (a class deriving from Shape), its input struct in
// scene/scene_input.h, one line in shapes/make_shape.cpp, and its tests (docs/architecture.md).
#include <embree3/rtcore.h>

#include <span>

#include "renderer/core/bounds.h"
#include "renderer/core/direction_cone.h"
#include "renderer/core/motion.h"
#include "renderer/core/ray.h"
#include "renderer/embree/handles.h"

namespace penumbra {

class TriangleMesh;
struct Parallelogram;

struct ShapeSample {
  vec3 p;           // point on the surface
  vec3 p_error;     // its absolute error bound
  vec3 n;           // unit geometric normal (front side)
  vec2 uv{0.f};     // surface coordinates of p, as a hit there would have (if the context's
                    // sample_uv asked for them; textured emitters)
  float pdf = 0.f;  // solid-angle density seen from the reference point (0 = failed)
};

// A shape's rigid motion over the camera's shutter. Times passed to shapes are normalised
// shutter times in [0, 1]; scene time = shutter_open + time * shutter_span.
struct ShapeMotion {
  Motion motion;
  float shutter_open = 0.f;
  float shutter_span = 0.f;

  bool is_static() const { return motion.is_static(); }
  // The exact displacement at normalised time `time`.
  vec3 displacement(float time) const { return motion.displacement(shutter_open + time * shutter_span); }
  // Componentwise bounds of the displacement over the whole shutter.
  Bounds3 displacement_bounds() const {
    Bounds3 b;
    motion.displacement_bounds(shutter_open, shutter_open + shutter_span, &b.lo, &b.hi);
    return b;
  }
};

// What a shape needs to know of the scene it is built into.
struct ShapeContext {
  ShapeMotion motion;
  vec3 offset{0.f};             // added to every position (motion baked in without a shutter)
  vec3 camera_position{0.f};    // picks how finely a moving mesh is tessellated in time
  bool emissive = false;        // an area light will sample it: prepare sampling by area
  bool need_uv = false;         // something reads SurfaceHit::uv (textures); else it may stay 0
  bool sample_uv = false;       // its emission is textured: samples need their uv
  // Triangle meshes: a cutout; hits where alpha_factor x alpha(uv) < alpha_cutoff are ignored.
  // The texture is owned by the scene and outlives the shape.
  const class FloatTexture* alpha = nullptr;
  float alpha_factor = 1.f;
  float alpha_cutoff = 0.5f;
};

class Shape {
 public:
  virtual ~Shape() = default;

  // A new Embree geometry for this shape, committed; its user data is this Shape, which must
  // outlive the Embree scene.
  virtual EmbreeGeometry make_geometry(RTCDevice device) const = 0;
  // World bounds over the whole shutter.
  virtual Bounds3 bounds() const = 0;
  // Surface area at time 0 (motion is rigid).
  virtual float area() const = 0;
  // Fills p, p_error, ng and ns of a hit Embree reported at distance t on primitive `prim` with
  // barycentrics `uv`. The point is rebuilt from the primitive, not taken as o + t*d, whose
  // error grows with t (pbrt-v4 section 6.8.4).
  virtual void hit_geometry(const Ray& ray, float t, uint32_t prim, const vec2& uv,
                            SurfaceHit* hit) const = 0;
  // Fills dpdu and dpdv of a hit hit_geometry filled (at normalised time `time`): the partial
  // derivatives of the surface point with respect to its uv (pbrt-v4 section 6.2.2). Asked only
  // for materials that need a tangent frame, so other hits do not pay for it.
  virtual void surface_derivatives(float time, SurfaceHit* hit) const = 0;
  // Samples a point of the surface as seen from `ref` at normalised time `time`; false if none.
  virtual bool sample(const vec3& ref, float time, const vec2& u, ShapeSample* out) const = 0;
  // Solid-angle density with which sample() yields point p (normal n) from ref.
  virtual float pdf(const vec3& ref, const vec3& p, const vec3& n, float time) const = 0;
  // A point on the shape at time 0 (the Embree-only benchmark aims its shadow rays at it).
  virtual vec3 reference_point() const = 0;
  // A cone holding the geometric normals of every point (the side a surface emits from as an
  // area light), for choosing among many lights (lights/light_bounds.h); the whole sphere when
  // the shape does not bound them more tightly. Motion is a translation: the same at every time.
  virtual DirectionCone normal_cone() const { return DirectionCone::whole_sphere(); }
  // The shape as Embree triangles (meshes and quads), else nullptr: the scene build decides
  // where their exact-t test runs (scene/exact_t_check.h) and looks for coincident triangles.
  virtual TriangleMesh* triangle_mesh() { return nullptr; }
  const TriangleMesh* triangle_mesh() const { return const_cast<Shape*>(this)->triangle_mesh(); }
  // The parallelograms it is traced as (a static quad's one, a mesh's face pairs), else none:
  // the scene build thickens the boxes of those that can tie with another object's
  // (scene/coplanar_parallelograms.h).
  virtual std::span<Parallelogram> parallelograms() { return {}; }
};

// Solid-angle density of picking point p (normal n) uniformly by area on a surface of `area`:
// the area density 1/area times dist^2 / |cos| (pbrt-v4 section 6.1.3).
inline float area_to_solid_angle(const vec3& ref, const vec3& p, const vec3& n, float area) {
  const vec3 w = p - ref;
  const float dist2 = glm::dot(w, w);
  const float cos_l = std::abs(glm::dot(n, w)) / std::sqrt(dist2);
  return cos_l > 0.f && area > 0.f ? dist2 / (cos_l * area) : 0.f;
}

}  // namespace penumbra
