#pragma once
// "materials": name -> {"type": diffuse | conductor | dielectric | plastic, ...}.
#include <map>
#include <string>
#include <vector>

#include "api/asset_path.h"
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
// names are kept in `index` so objects naming them get no second, misleading error.
ParsedMaterials parse_materials(const Json* materials, const std::string& pointer,
                                const Limits& limits, const AssetFolder& assets, Diagnostics& diag);

}  // namespace penumbra::api
