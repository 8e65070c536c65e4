#pragma once
// One placed copy of a mesh: an Embree instance (RTC_GEOMETRY_TYPE_INSTANCE) of a child scene
// that holds the mesh's own geometry, so every copy shares one BVH and one set of vertex
// buffers. What a copy keeps here is its transform and what turning a hit in the child back into
// a world-space hit needs.
//
// Hits are rebuilt as pbrt-v4 does for transformed shapes (section 6.8 and its Transform error
// bounds): the shape rebuilds the point in object space with its error bound, then the point is
// transformed with the bound carried through, normals by the cofactor matrix (the inverse
// transpose times det: a mirror turns the front side round exactly as transforming the vertices
// by hand does), uv unchanged.
#include <embree3/rtcore.h>

#include "renderer/core/bounds.h"
#include "renderer/core/ray.h"
#include "renderer/embree/handles.h"
#include "renderer/scene/instance_input.h"

namespace penumbra {

class Shape;

class Instance {
 public:
  // `shape` (the mesh) must outlive the instance; `object` is the mesh's object index, which a
  // hit on the copy reports (material, no area light).
  Instance(const Shape& shape, uint32_t object, const InstanceTransform& transform);

  // A new committed Embree instance geometry of `child` (a committed scene holding the shape).
  EmbreeGeometry make_geometry(RTCDevice device, RTCScene child) const;
  // World bounds over the shutter: the shape's bounds transformed.
  Bounds3 bounds() const;
  uint32_t object() const { return object_; }
  const glm::mat3& linear() const { return linear_; }
  const vec3& translation() const { return translation_; }

  // Fills hit->p, p_error, ng, ns, uv for a hit Embree reported on primitive `prim` of the child
  // with barycentrics `uv` at world distance t (an instance's ray parameter is the world one:
  // Embree transforms the direction without normalising it).
  void hit_geometry(const Ray& world_ray, float t, uint32_t prim, const vec2& uv,
                    SurfaceHit* hit) const;
  // dp/du and dp/dv of a hit hit_geometry filled: the mesh's, in its space, mapped by the
  // linear part (tangent vectors transform as the points' differences do).
  void surface_derivatives(float time, SurfaceHit* hit) const;

 private:
  const Shape* shape_;
  glm::mat3 linear_;        // object (the mesh's world) -> this copy
  vec3 translation_;
  glm::mat3 cofactor_;      // det(linear) * inverse transpose: maps normals, keeps handedness
  glm::mat3 inverse_;       // this copy -> object
  vec3 inverse_translation_;
  float inverse_slack_;     // relative error bound of Embree's own float inverse (see .cpp)
  uint32_t object_;
};

// A committed child scene holding `geometry` alone (a mesh's geometry, attached to the top-level
// scene too: Embree lets one geometry belong to several scenes, so the copies add no vertex
// buffers). Its geometry id is 0. `flags` are the top-level scene's (Embree needs
// RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION on every scene a context filter should reach).
EmbreeScene make_instanced_scene(RTCDevice device, RTCGeometry geometry,
                                 RTCSceneFlags flags = RTC_SCENE_FLAG_ROBUST);

}  // namespace penumbra
