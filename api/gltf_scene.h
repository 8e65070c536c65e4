#pragma once
// A scene around a glTF asset, for `penumbra render model.glb` and `penumbra info model.glb`:
// the asset as one "gltf" object, seen through its first camera (or a camera that frames its
// bounding box), lit by its KHR_lights_punctual lights (or, without any, a neutral white
// environment). The scene is written as scene-format JSON and loaded as any scene is, so
// render flags override it and every check applies.
#include <span>
#include <string>

#include "api/scene_loader.h"

namespace penumbra::api {

// The scene document for the glTF file `path`; errors (reading the asset) in `result`.
LoadResult load_gltf_scene_file(const std::string& path, const Limits& limits = {},
                                std::span<const RenderOverride> overrides = {});

// The JSON text load_gltf_scene_file renders (for `penumbra info` and tests); empty on error,
// with the errors in `result`.
std::string gltf_scene_document(const std::string& path, const Limits& limits, LoadResult* result);

}  // namespace penumbra::api
