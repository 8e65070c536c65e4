#pragma once
// Which files a finished job's result is, by name in the ResultStore (docs/output-layers.md):
//   "exr", "png"            the beauty image (the EXR with the output layers as extra channels,
//                           plain names: albedo.R, normal.X, depth.Z)
//   "blender.exr"           beauty and layers in Blender's multi-layer layout (jobs with layers)
//   "<layer>.exr", ".png"   one output layer alone (albedo, normal, depth)
// An animation's frames keep the same names under "frames/<frame>." (frame_result_key): frame 17's
// PNG is "frames/17.png", its albedo EXR "frames/17.albedo.exr".
#include <optional>
#include <string>
#include <vector>

#include "renderer/core/image.h"
#include "server/storage/result_store.h"

namespace penumbra::server {

// The store key of a result: `layer` "" for the beauty image, `blender` for the Blender layout
// (EXR only), `extension` "png" or "exr".
std::string result_key(const std::string& layer, bool blender, const std::string& extension);

// Every key a still's result may have (what a removal deletes; frames go as one folder).
const std::vector<std::string>& all_result_keys();

// The store key of `key` (as result_key makes it) for frame `frame` of an animation.
std::string frame_result_key(int frame, const std::string& key);
// The folder prefix every frame key of a job starts with ("frames/").
inline constexpr const char* kFramesKeyPrefix = "frames/";

// Encodes and writes them all: the beauty EXR (with the layers' channels) and PNG, and when
// there are layers the Blender EXR and each layer's EXR and PNG. Throws as ResultStore::write and encoding do.
// `frame`: an animation's frame, stored under frame_result_key (nullopt: a still).
void write_results(ResultStore& store, const std::string& id, const Image& image,
                   const std::vector<ImageLayer>& layers, const ImageMetadata& metadata,
                   std::optional<int> frame = std::nullopt);

}  // namespace penumbra::server
