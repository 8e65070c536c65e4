#pragma once
#include <string>

namespace penumbra::api {
// The JSON documents kept in api/ (scene.schema.json, openapi.json, ...), compiled into the
// binary. Returns nullptr for an unknown name.
const std::string* embedded_document(const std::string& name);
}  // namespace penumbra::api
