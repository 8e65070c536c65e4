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

  JsonDocument() = default;
  JsonDocument(JsonDocument&&) = default;
  JsonDocument& operator=(JsonDocument&&) = default;
  JsonDocument(const JsonDocument&) = default;
  JsonDocument& operator=(const JsonDocument&) = default;
  // Empties the value's containers from the leaves up before it is destroyed: nlohmann 3.11's
  // destructor (its guard against deep recursion) first moves every array's elements into a
  // second vector, for an inline mesh's arrays a copy of megabytes. The depth is the parse's cap.
  ~JsonDocument();
};

// Syntax errors are reported on pointer "" with the byte offset in the message; duplicate keys
// are ordinary (kInvalid) errors on the duplicated member's pointer.
// Two parsers behind one result: simdjson's (parse_json_fast) for documents it vouches for, and
// nlohmann's (the reference) for everything else, so every diagnostic is nlohmann's and the
// reference's. The fuzz target json_document checks that the two build equal values.
JsonDocument parse_json_document(std::string_view text, int max_depth, Diagnostics& diag);

// The value nlohmann's parser would build, or nullopt where this path defers to it: anything
// simdjson rejects (malformed JSON, numbers out of range, integers beyond 64 bits, nesting past
// its 1024 levels), a duplicate key, nesting at max_depth, a string that unescapes to invalid
// UTF-8. Numbers: negative integers are number_integer, others number_unsigned, the rest float
// (nlohmann keeps "-0" as number_integer 0, this path as number_unsigned 0).
std::optional<Json> parse_json_fast(std::string_view text, int max_depth);

// nlohmann's parser alone, with the depth cap and duplicate keys tracked: the reference.
JsonDocument parse_json_document_reference(std::string_view text, int max_depth,
                                           Diagnostics& diag);

}  // namespace penumbra::api
