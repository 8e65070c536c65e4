#pragma once
// A header or query parameter of a request as an optional: absent is not the same as empty.
#include <httplib.h>

#include <optional>
#include <string>

namespace penumbra::server {

inline std::optional<std::string> header_value(const httplib::Request& req, const char* name) {
  if (!req.has_header(name)) return std::nullopt;
  return req.get_header_value(name);
}

inline std::optional<std::string> param_value(const httplib::Request& req, const char* name) {
  if (!req.has_param(name)) return std::nullopt;
  return req.get_param_value(name);
}

}  // namespace penumbra::server
