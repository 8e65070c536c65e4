#pragma once
// What rendering a scene will hold in memory, estimated from its input without building it (for
// `penumbra info` and admission decisions). Sizes follow the data structures; Embree's BVH is a
// per-triangle figure measured with its memory monitor (see memory_estimate.cpp).
#include <cstdint>

#include "renderer/scene/scene_input.h"

namespace penumbra {

struct MemoryEstimate {
  int64_t scene_input = 0;        // the SceneInput itself (mesh arrays)
  int64_t shapes = 0;             // the renderer's copies (triangle meshes, light sampling tables)
  int64_t embree = 0;             // Embree's vertex and index buffers and its BVH, after the build
  int64_t embree_build_peak = 0;  // the build's transient extra on top of `embree`
  int64_t film = 0;               // per-pixel accumulators and the output images
  // Decoded image textures: their sizes come from the files' headers, which a SceneInput does
  // not hold, so the caller fills this (api's SceneRequest::texture_bytes).
  int64_t textures = 0;
  int64_t total() const {
    return scene_input + shapes + embree + embree_build_peak + film + textures;
  }
};

MemoryEstimate estimate_memory(const SceneInput& scene, const RenderSettings& settings);
// One mesh on its own (no film), static and not emitting.
MemoryEstimate estimate_mesh_memory(const MeshDesc& mesh);

}  // namespace penumbra
