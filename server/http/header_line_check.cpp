#include "server/http/header_line_check.h"

#include <string>

#include "server/text_util.h"

namespace penumbra::server {
namespace {

// RFC 9110 section 5.5: field-vchar / SP / HTAB (obs-text, bytes >= 0x80, is allowed too).
bool is_field_value_char(unsigned char c) { return c == '\t' || (c >= 0x20 && c != 0x7f); }

// The field name, for messages: only token characters are echoed.
std::string printable_name(std::string_view name) {
  std::string out;
  for (char c : name.substr(0, 64))
    out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '?';
  return out;
}

}  // namespace

std::optional<Problem> check_head_line(std::string_view line, std::size_t index,
                                       const ConnectionLimits& limits) {
  if (index == 0) {
    for (unsigned char c : line)
      if (c < 0x20 || c == 0x7f)
        return make_problem(400, "bad-request-line", "Bad Request",
                            "the request line contains a control character");
    return std::nullopt;
  }
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos || colon == 0)
    return make_problem(400, "bad-header", "Bad Request",
                        "a header line has no field name followed by ':'");
  const std::string_view name = line.substr(0, colon);
  for (unsigned char c : name)
    if (c <= 0x20 || c >= 0x7f || c == '(' || c == ')' || c == ',' || c == '/' || c == ':' ||
        c == ';' || c == '<' || c == '=' || c == '>' || c == '?' || c == '@' || c == '[' ||
        c == '\\' || c == ']' || c == '{' || c == '}' || c == '"')
      return make_problem(400, "bad-header", "Bad Request",
                          "a header field name contains a character outside RFC 9110's token");
  const std::string_view value = line.substr(colon + 1);
  for (unsigned char c : value)
    if (!is_field_value_char(c)) {
      Problem p = make_problem(400, "bad-header", "Bad Request",
                               "header " + printable_name(name) +
                                   " contains a control character (NUL, CR, LF or another "
                                   "byte below 0x20); RFC 9110 section 5.5 forbids them");
      p.extensions["header"] = printable_name(name);
      return p;
    }
  if (ascii_lower(std::string(name)) == "range" &&
      trim_ows(value).size() > limits.max_range_bytes) {
    // cpp-httplib matches Range with a backtracking std::regex before any handler runs; one
    // byte range never needs more than this.
    return make_problem(416, "multiple-ranges", "Range Not Satisfiable",
                        "the Range header is longer than " +
                            std::to_string(limits.max_range_bytes) +
                            " bytes; only a single byte range is served");
  }
  return std::nullopt;
}

}  // namespace penumbra::server
