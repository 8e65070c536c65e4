#pragma once
// Small ASCII string helpers for HTTP headers and URLs (server/http/ and server/jobs/).
#include <cctype>
#include <string>
#include <string_view>

namespace penumbra::server {

inline std::string ascii_lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Without leading and trailing spaces and tabs (optional whitespace of RFC 9110 section 5.6.3).
inline std::string_view trim_ows(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace penumbra::server
