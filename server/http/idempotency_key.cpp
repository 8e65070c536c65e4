#include "server/http/idempotency_key.h"

#include <algorithm>

#include "server/text_util.h"

namespace penumbra::server {

std::variant<std::string, Problem> parse_idempotency_key(const std::optional<std::string>& header) {
  if (!header) return std::string();
  std::string_view key = trim_ows(*header);
  // The draft sends it as a quoted structured-field string (RFC 8941 section 3.3.3).
  if (key.size() >= 2 && key.front() == '"' && key.back() == '"')
    key = key.substr(1, key.size() - 2);
  const bool visible =
      std::all_of(key.begin(), key.end(), [](char c) { return c > 0x20 && c < 0x7f; });
  if (key.empty() || key.size() > kMaxIdempotencyKeyLength || !visible)
    return make_problem(400, "invalid-idempotency-key", "Invalid Idempotency-Key",
                        "Idempotency-Key must be 1 to 255 visible ASCII characters");
  return std::string(key);
}

}  // namespace penumbra::server
