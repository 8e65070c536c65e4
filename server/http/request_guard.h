#pragma once
// Checks run on every request before routing, before the body is read. cpp-httplib 0.11.4 would
// otherwise accept chunked bodies past the payload limit, inflate gzip bodies without bound and
// build multipart responses for many ranges.
#include <cstddef>
#include <optional>

#include "server/http/auth.h"
#include "server/http/problem.h"

namespace httplib {
struct Request;
}

namespace penumbra::server {

struct GuardSettings {
  std::size_t max_body_bytes = 0;
  // PUT /v1/assets/{sha256} bodies (--max-asset-size) instead of max_body_bytes.
  std::size_t max_asset_bytes = 0;
};

// The problem to answer instead of routing, or nullopt to let the request through.
std::optional<Problem> guard_request(const httplib::Request& req, const GuardSettings& settings,
                                     const BearerAuth& auth);

}  // namespace penumbra::server
