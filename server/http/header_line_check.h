#pragma once
// Checks one line of a request head as it arrives, before cpp-httplib parses it: the limits of
// ConnectionLimits and the characters RFC 9110 section 5.5 allows in a field value. The library
// keeps a value up to a NUL and then reads it through c_str(), which cut "Bearer TOKEN\0junk" to a
// valid token; a control character is refused here instead.
#include <optional>
#include <string_view>

#include "server/http/connection_limits.h"
#include "server/http/problem.h"

namespace penumbra::server {

// line: one line of the head without its CR LF; index 0 is the request line.
std::optional<Problem> check_head_line(std::string_view line, std::size_t index,
                                       const ConnectionLimits& limits);

}  // namespace penumbra::server
