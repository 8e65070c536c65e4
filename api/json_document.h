#pragma once
// Text -> nlohmann::json, safely: nesting depth capped (nlohmann parses iteratively, but copying
// and dump() recurse), every exception caught, duplicate object keys reported (nlohmann would
// silently keep the last one, a silent fix-up we refuse).
#include <optional>
#include <string_view>

#include "api/diagnostics.h"
#include "api/json_reader.h"

namespace penumbra::api {

struct JsonDocument {
  std::optional<Json> value;      // set unless there was a syntax error
  bool syntax_error = false;      // kSyntax: malformed, or nested deeper than the cap
};

// Syntax errors are reported on pointer "" with the byte offset in the message; duplicate keys
// are ordinary (kInvalid) errors on the duplicated member's pointer.
JsonDocument parse_json_document(std::string_view text, int max_depth, Diagnostics& diag);

}  // namespace penumbra::api
