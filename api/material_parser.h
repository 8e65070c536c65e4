#pragma once
// "materials": name -> {"type": diffuse | conductor | dielectric | plastic, ...}. A colour or
// roughness may be a texture (api/texture_parser.h); every material may have a normal_map.
#include <map>
#include <string>
#include <vector>

#include "api/json_reader.h"
#include "api/scene_loader.h"
#include "renderer/materials/material_params.h"


namespace penumbra::api {

struct ParsedMaterials {
  std::vector<MaterialParams> params;         // in the order of `names`
  std::vector<std::string> names;             // index = material handle in SceneInput
  std::map<std::string, uint32_t> index;      // name -> handle
};

// Materials with errors are left out of the result (their errors are in `diag`), but their
// names are kept in `index` so objects naming them get no second, misleading error. Texture
// files are resolved, probed and counted through `textures`.
class TextureSet;
ParsedMaterials parse_materials(const Json* materials, const std::string& pointer,
                                const Limits& limits, TextureSet& textures, Diagnostics& diag);

}  // namespace penumbra::api
