#pragma once
// A small scene with everything whose sampling a split frame must reproduce: glass, depth of
// field, an image texture, motion blur, and an animation for the frame tests.
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "app_test_util.h"

namespace penumbra::test {

inline nlohmann::json split_frame_scene() {
  return nlohmann::json::parse(R"({
    "version": 1,
    "render": {"width": 40, "height": 30, "spp": 16, "max_depth": 8, "seed": 7},
    "camera": {"position": [0, 1, 4.5], "look_at": [0, 0.5, 0], "fov": 40,
               "aperture_radius": 0.08, "focus_distance": 4.4, "shutter": [0, 1]},
    "environment": {"radiance": [0.2, 0.22, 0.25]},
    "materials": {
      "floor": {"type": "diffuse", "color": {"texture": "checker.png", "filter": "nearest"}},
      "glass": {"type": "dielectric", "ior": 1.5},
      "red": {"type": "diffuse", "color": [0.7, 0.1, 0.1]},
      "lamp": {"type": "diffuse", "color": [0, 0, 0]}
    },
    "objects": [
      {"type": "quad", "origin": [-3, 0, 3], "u": [6, 0, 0], "v": [0, 0, -6], "material": "floor"},
      {"type": "sphere", "center": [-0.6, 0.5, 0], "radius": 0.5, "material": "glass"},
      {"type": "sphere", "center": [0.7, 0.4, 0.3], "radius": 0.4, "material": "red",
       "velocity": [0.5, 0.2, 0], "acceleration": [0, -0.4, 0]},
      {"type": "quad", "origin": [-1, 2.5, -1], "u": [2, 0, 0], "v": [0, 0, 2], "material": "lamp",
       "emission": [6, 6, 6]}
    ]
  })");
}

// Writes `scene` as scene.json into `folder`, with the texture it names.
inline void write_split_frame_scene(const SceneFolder& folder, const nlohmann::json& scene) {
  std::filesystem::copy_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/textures/checker.png",
                             folder.file("checker.png"),
                             std::filesystem::copy_options::overwrite_existing);
  std::ofstream(folder.file("scene.json")) << scene.dump(2);
}

}  // namespace penumbra::test
