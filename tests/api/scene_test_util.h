#pragma once
// Helpers shared by the api tests: a small valid scene to mutate, and error lookups.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "api/scene_loader.h"

namespace penumbra::test {

// The api tests name api's types and functions as its own code does.
using namespace api;
using Json = nlohmann::json;

// Valid, lit, minimal: one emitting sphere, one material.
inline Json base_scene() {
  return Json::parse(R"({
    "version": 1,
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": {"white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white",
                 "emission": [1, 1, 1]}]
  })");
}

// The loader puts the renderer's origin at the camera (SceneRequest::world_origin); the tests
// state positions in the JSON's coordinates, so add the origin back in double precision.
inline void restore_json_coordinates(SceneRequest& r) {
  auto add = [&](vec3& p) { p = vec3(glm::dvec3(p) + r.world_origin); };
  add(r.scene.camera.position);
  add(r.scene.camera.look_at);
  for (ObjectDesc& o : r.scene.objects) {
    if (auto* s = std::get_if<SphereDesc>(&o.shape)) add(s->center);
    if (auto* q = std::get_if<QuadDesc>(&o.shape)) add(q->origin);
    if (auto* m = std::get_if<MeshDesc>(&o.shape))
      for (vec3& p : m->positions) add(p);
  }
  for (LightDesc& l : r.scene.lights)
    if (auto* p = std::get_if<PointLightDesc>(&l)) add(p->position);
}

inline LoadResult load(const Json& scene, const Limits& limits = {}) {
  LoadResult r = load_scene(scene.dump(), limits);
  if (r.request) restore_json_coordinates(*r.request);
  return r;
}

inline std::string describe(const std::vector<Diagnostic>& list) {
  std::string text;
  for (const Diagnostic& d : list) text += "  " + d.to_string() + "\n";
  return text;
}

// True when some diagnostic has exactly this pointer and its message contains `fragment`.
inline bool has(const std::vector<Diagnostic>& list, const std::string& pointer,
                const std::string& fragment = "") {
  for (const Diagnostic& d : list)
    if (d.pointer == pointer && d.message.find(fragment) != std::string::npos) return true;
  return false;
}

}  // namespace penumbra::test

// Asserts an error at `pointer` (message containing `fragment`) and that the load failed.
#define EXPECT_ERROR(result, pointer, fragment)                                           \
  do {                                                                                    \
    const auto& r_ = (result);                                                            \
    EXPECT_FALSE(r_.ok());                                                                \
    EXPECT_FALSE(r_.request.has_value());                                                 \
    EXPECT_TRUE(::penumbra::test::has(r_.errors, pointer, fragment))                 \
        << "expected error at " << (pointer) << " containing '" << (fragment) << "', got:\n" \
        << ::penumbra::test::describe(r_.errors);                                    \
  } while (0)

#define EXPECT_LOADS(result)                                                                \
  do {                                                                                      \
    const auto& r_ = (result);                                                              \
    EXPECT_TRUE(r_.ok()) << ::penumbra::test::describe(r_.errors);                     \
    EXPECT_EQ(r_.kind, ::penumbra::api::LoadErrorKind::kNone);                              \
    EXPECT_TRUE(r_.request.has_value());                                                    \
  } while (0)
