#pragma once
// The signature a webhook carries: X-Penumbra-Signature: sha256=<hex of HMAC-SHA256(secret,
// body)> (RFC 2104 HMAC over the exact body bytes, as GitHub's X-Hub-Signature-256). A receiver
// recomputes it with the job's secret and compares in constant time.
#include <string>
#include <string_view>

namespace penumbra::server {

// 64 lowercase hex digits.
std::string hmac_sha256_hex(std::string_view secret, std::string_view body);
// "sha256=" + hmac_sha256_hex(secret, body).
std::string webhook_signature(std::string_view secret, std::string_view body);

}  // namespace penumbra::server
