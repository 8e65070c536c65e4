#pragma once
// Bearer-token authentication (RFC 6750), one shared token for the whole service.
#include <string>
#include <string_view>

namespace penumbra::server {

// Compares in time that depends only on the lengths, never on where the first difference is,
// so response timing does not reveal a token prefix.
bool constant_time_equal(std::string_view a, std::string_view b);

class BearerAuth {
 public:
  explicit BearerAuth(std::string token) : token_(std::move(token)) {}
  bool enabled() const { return !token_.empty(); }
  // The value of an Authorization header; true when it carries the token (or auth is off).
  bool allows(std::string_view authorization_header) const;

 private:
  std::string token_;
};

}  // namespace penumbra::server
