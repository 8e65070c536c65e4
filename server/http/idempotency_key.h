#pragma once
// The Idempotency-Key request header (draft-ietf-httpapi-idempotency-key-header): 1 to 255
// visible ASCII characters, bare or as a quoted structured-field string.
#include <optional>
#include <string>
#include <variant>

#include "server/http/problem.h"

namespace penumbra::server {

constexpr std::size_t kMaxIdempotencyKeyLength = 255;

// The key ("" when the header is absent), or a 400 problem.
std::variant<std::string, Problem> parse_idempotency_key(const std::optional<std::string>& header);

}  // namespace penumbra::server
