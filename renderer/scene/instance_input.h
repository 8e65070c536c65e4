#pragma once
// Instancing input: copies of one mesh object placed by affine transforms. The renderer makes
// them Embree instances of one BVH (shapes/instance.h), so a copy costs a transform and an
// Embree instance record, not the mesh.
#include <cstdint>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

// p' = linear * p + translation, from the mesh's world space (where the mesh object stands, its
// own transform and the camera rebasing already applied) to the copy's. `linear` is invertible.
struct InstanceTransform {
  glm::mat3 linear{1.f};
  vec3 translation{0.f};
};

// The copies of SceneInput::objects[object], which must be a static or moving mesh that does not
// emit (Scene::build refuses anything else); they share its material.
struct InstancesDesc {
  uint32_t object = 0;
  std::vector<InstanceTransform> transforms;
};

}  // namespace penumbra
