#pragma once
// Whether a listen address is reachable from this machine only: decided on addresses, never on the
namespace penumbra::server {}
#include <string>

namespace penumbra::server {

// True when `host` resolves (getaddrinfo, as the bind does) and every address it resolves to is
// in 127.0.0.0/8, ::1 or ::ffff:127.0.0.0/104. False for wildcard addresses and unresolvable names.
bool is_loopback_host(const std::string& host);
// True when the socket's own bound address (getsockname) is a loopback address.
bool is_loopback_socket(int fd);

}  // namespace penumbra::server
