#pragma once
// The render scene: built once from a SceneInput (Embree BVH, lights, materials), then immutable
// and shared const by every render thread.
#include <memory>
#include <stdexcept>

#include "renderer/scene/scene_input.h"

namespace penumbra {

struct SceneBuildError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class SceneImpl;  // renderer-internal

class Scene {
 public:
  // Throws SceneBuildError (e.g. an Embree failure). Input is assumed validated.
  static std::unique_ptr<Scene> build(const SceneInput& input);
  ~Scene();

  const SceneImpl& impl() const { return *impl_; }

 private:
  explicit Scene(std::unique_ptr<SceneImpl> impl);
  std::unique_ptr<SceneImpl> impl_;
};

}  // namespace penumbra
