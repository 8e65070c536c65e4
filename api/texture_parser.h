#pragma once
// Material parameters and emission given by an image: `{"texture": PATH, "colorspace": ...,
// "channel": ..., "scale": ..., "wrap": ..., "filter": ...}` where a constant would stand, and a
// material's `normal_map` (docs/scene-format.md, "Textures"). Every image file is resolved inside
// the scene's asset folder and its header read (never its pixels) against the texture limits.
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/asset_path.h"
#include "api/json_reader.h"
#include "api/scene_loader.h"
#include "renderer/io/image_reader.h"
#include "renderer/textures/texture_desc.h"

namespace penumbra::api {

// The distinct images a scene's textures use, each probed once, and their decoded size against
// Limits::max_texture_bytes. One per scene load, shared by the material and object parsers.
class TextureSet {
 public:
  TextureSet(const Limits& limits, const AssetFolder& assets) : limits_(limits), assets_(assets) {}

  // The header of the image at `path` (relative to the asset folder), resolved and checked
  // against the per-image limit, with the file's canonical path; nullopt with an error on
  // `pointer` (the field holding the path).
  std::optional<std::pair<std::string, AssetImageInfo>> probe(const std::string& path,
                                                              const std::string& pointer,
                                                              Diagnostics& diag);
  // Counts a decoded image (file, colorspace) once against max_texture_bytes; false with an
  // error on `pointer` when it does not fit.
  bool reserve(const std::string& file, TextureColorspace colorspace, const AssetImageInfo& info,
               const std::string& pointer, Diagnostics& diag);

  // The header of an image held in memory (a glTF asset's), checked against the per-image limit;
  // `key` names it uniquely in the scene (ImageTextureDesc::path). nullopt with an error on
  // `pointer`, naming the image as source.path does.
  std::optional<AssetImageInfo> probe_memory(const std::string& key, const ImageSource& source,
                                             const std::string& pointer, Diagnostics& diag);

  // Channels of a file probe() accepted.
  int channels(const std::string& file) const { return channels_.at(file); }
  TextureLimits renderer_limits() const {
    return {limits_.max_texture_pixels, limits_.max_texture_bytes};
  }
  int64_t bytes() const { return bytes_; }
  // The image files probe() accepted, once each, in the order fields first named them.
  const std::vector<AssetUse>& uses() const { return uses_; }

 private:
  const Limits& limits_;
  const AssetFolder& assets_;
  std::map<std::string, std::optional<std::pair<std::string, AssetImageInfo>>>
      probed_;                           // by path as written
  std::map<std::string, std::optional<AssetImageInfo>> memory_probed_;  // by key
  std::map<std::string, int> channels_;  // by canonical file (or key)
  std::map<std::pair<std::string, TextureColorspace>, int64_t> reserved_;
  int64_t bytes_ = 0;
  std::vector<AssetUse> uses_;
};

// What a texture stands for: its default colorspace, whether `channel` and `scale` apply.
enum class TextureRole {
  kReflectance,  // a colour in [0, 1] (color): sRGB for integer images
  kEmission,     // radiance >= 0: sRGB for integer images
  kValue,        // one number (roughness) read from `channel`: linear
  kNormalMap,    // tangent-space normals, (n + 1) / 2: linear, no scale
};

// A parameter that is a constant or a texture: the value is `factor` (the constant, or the
// texture's `scale`) times the texture's value at the hit, if there is one.
struct SpectrumField {
  Spectrum factor{1.f};
  std::optional<ImageTextureDesc> texture;
};
struct FloatField {
  float factor = 1.f;
  std::optional<ImageTextureDesc> texture;
};

// The member `key`: an [r, g, b] array in `range`, or a texture object whose scale (a number or
// [r, g, b]) lies in `range`. nullopt when absent or invalid (errors reported).
std::optional<SpectrumField> read_spectrum_field(ObjectReader& reader, std::string_view key,
                                                 const Range& range, TextureRole role,
                                                 TextureSet& textures);
// The member `key`: a number in `range`, or a texture object (role kValue) whose scale lies in
// `range`.
std::optional<FloatField> read_float_field(ObjectReader& reader, std::string_view key,
                                           const Range& range, TextureSet& textures);
// The member `key`: a file name, or a texture object with only `texture`, `wrap` and `filter`.
std::optional<ImageTextureDesc> read_normal_map(ObjectReader& reader, std::string_view key,
                                                TextureSet& textures);

}  // namespace penumbra::api
