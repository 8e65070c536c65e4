#pragma once
// JSON answers: the body pretty-printed as the API documents show it.
#include <nlohmann/json.hpp>
#include <vector>

#include "api/scene_loader.h"

namespace httplib {
struct Response;
}

namespace penumbra::server {

void send_json(httplib::Response& res, int status, const nlohmann::ordered_json& body);
// [{pointer, detail}] of scene diagnostics.
nlohmann::ordered_json diagnostics_json(const std::vector<api::Diagnostic>& diagnostics);

}  // namespace penumbra::server
