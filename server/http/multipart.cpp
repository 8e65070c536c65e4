#include "server/http/multipart.h"

#include <algorithm>
#include <cctype>

#include "server/text_util.h"

namespace penumbra::server {
namespace {

// One parameter value after '=': a token, or a quoted-string with backslash escapes (RFC 9110
// section 5.6.4). Advances `s` past it; nullopt when a quote is not closed.
std::optional<std::string> read_param_value(std::string_view& s) {
  std::string out;
  if (!s.empty() && s.front() == '"') {
    s.remove_prefix(1);
    while (!s.empty() && s.front() != '"') {
      if (s.front() == '\\' && s.size() > 1) s.remove_prefix(1);
      out += s.front();
      s.remove_prefix(1);
    }
    if (s.empty()) return std::nullopt;
    s.remove_prefix(1);
    return out;
  }
  const auto end = s.find(';');
  out = std::string(trim_ows(s.substr(0, end)));
  s.remove_prefix(end == std::string_view::npos ? s.size() : end);
  return out;
}

// "form-data; name=\"x\"; filename=\"y\"" -> name, filename; false when malformed.
bool parse_disposition(std::string_view value, MultipartPart& part, std::string& error) {
  const auto semi = value.find(';');
  if (ascii_lower(std::string(trim_ows(value.substr(0, semi)))) != "form-data") {
    error = "a part's Content-Disposition must be form-data";
    return false;
  }
  if (semi == std::string_view::npos) {
    error = "a part has no name";
    return false;
  }
  std::string_view rest = value.substr(semi + 1);
  bool has_name = false;
  while (!trim_ows(rest).empty()) {
    rest = trim_ows(rest);
    const auto eq = rest.find('=');
    if (eq == std::string_view::npos) {
      error = "a Content-Disposition parameter has no value";
      return false;
    }
    const std::string key = ascii_lower(std::string(trim_ows(rest.substr(0, eq))));
    rest.remove_prefix(eq + 1);
    rest = trim_ows(rest);
    const auto v = read_param_value(rest);
    if (!v) {
      error = "a quoted Content-Disposition parameter is not closed";
      return false;
    }
    if (key == "name") {
      if (has_name) {
        error = "a part has two names";
        return false;
      }
      part.name = *v;
      has_name = true;
    } else if (key == "filename") {
      part.filename = *v;
    }
    rest = trim_ows(rest);
    if (!rest.empty()) {
      if (rest.front() != ';') {
        error = "Content-Disposition parameters must be separated by ';'";
        return false;
      }
      rest.remove_prefix(1);
    }
  }
  if (!has_name) {
    error = "a part has no name";
    return false;
  }
  return true;
}

}  // namespace

std::optional<std::string> multipart_boundary(std::string_view content_type) {
  const auto semi = content_type.find(';');
  if (ascii_lower(std::string(trim_ows(content_type.substr(0, semi)))) != "multipart/form-data" ||
      semi == std::string_view::npos)
    return std::nullopt;
  std::string_view rest = content_type.substr(semi + 1);
  while (!trim_ows(rest).empty()) {
    rest = trim_ows(rest);
    const auto eq = rest.find('=');
    if (eq == std::string_view::npos) return std::nullopt;
    const std::string key = ascii_lower(std::string(trim_ows(rest.substr(0, eq))));
    rest.remove_prefix(eq + 1);
    rest = trim_ows(rest);
    const auto v = read_param_value(rest);
    if (!v) return std::nullopt;
    if (key == "boundary") {
      if (v->empty() || v->size() > 70) return std::nullopt;
      return v;
    }
    rest = trim_ows(rest);
    if (!rest.empty() && rest.front() == ';') rest.remove_prefix(1);
  }
  return std::nullopt;
}

MultipartResult parse_multipart(std::string_view body, std::string_view boundary,
                                const MultipartLimits& limits) {
  MultipartResult out;
  const std::string dash = "--" + std::string(boundary);
  const std::string delimiter = "\r\n" + dash;
  // The first boundary may follow a preamble (ignored) or open the body.
  std::size_t pos;
  if (body.substr(0, dash.size()) == dash) {
    pos = dash.size();
  } else {
    const auto at = body.find(delimiter);
    if (at == std::string_view::npos) {
      out.error = "the body has no multipart boundary '" + std::string(boundary) + "'";
      return out;
    }
    pos = at + delimiter.size();
  }
  for (;;) {
    // After a boundary: "--" ends the body, CRLF starts a part (transport padding allowed).
    while (pos < body.size() && (body[pos] == ' ' || body[pos] == '\t')) ++pos;
    if (body.substr(pos, 2) == "--") return out;
    if (body.substr(pos, 2) != "\r\n") {
      out.error = "a multipart boundary is not followed by a line break";
      return out;
    }
    pos += 2;
    if (out.parts.size() >= limits.max_parts) {
      out.error = "the form has more than " + std::to_string(limits.max_parts) + " parts";
      return out;
    }
    const auto head_end = body.find("\r\n\r\n", pos);
    // A part with no headers has its blank line at once.
    const bool empty_head = body.substr(pos, 2) == "\r\n";
    if (!empty_head && (head_end == std::string_view::npos ||
                        head_end - pos > limits.max_part_head_bytes)) {
      out.error = head_end == std::string_view::npos
                      ? "a part's headers do not end"
                      : "a part's headers exceed " + std::to_string(limits.max_part_head_bytes) +
                            " bytes";
      return out;
    }
    MultipartPart part;
    bool has_disposition = false;
    std::size_t lines = 0;
    if (!empty_head) {
      std::string_view head = body.substr(pos, head_end - pos);
      while (!head.empty()) {
        const auto eol = head.find("\r\n");
        const std::string_view line = head.substr(0, eol);
        head.remove_prefix(eol == std::string_view::npos ? head.size() : eol + 2);
        if (++lines > limits.max_part_headers) {
          out.error = "a part has more than " + std::to_string(limits.max_part_headers) + " headers";
          return out;
        }
        const auto colon = line.find(':');
        if (colon == std::string_view::npos || colon == 0) {
          out.error = "a part's header line has no name";
          return out;
        }
        const std::string key = ascii_lower(std::string(trim_ows(line.substr(0, colon))));
        const std::string_view value = trim_ows(line.substr(colon + 1));
        if (key == "content-disposition") {
          if (has_disposition) {
            out.error = "a part has two Content-Disposition headers";
            return out;
          }
          has_disposition = true;
          if (!parse_disposition(value, part, out.error)) return out;
        } else if (key == "content-type") {
          part.content_type = std::string(value);
        }
      }
      pos = head_end + 4;
    } else {
      pos += 2;
    }
    if (!has_disposition) {
      out.error = "a part has no Content-Disposition";
      return out;
    }
    // A delimiter is the boundary followed by "--" or (after optional white space) a line
    // break (RFC 2046 section 5.1.1); "--B" inside a line is data, however unwise the sender's
    // choice of boundary.
    std::size_t end = body.find(delimiter, pos);
    while (end != std::string_view::npos) {
      std::size_t after = end + delimiter.size();
      if (body.substr(after, 2) == "--") break;
      while (after < body.size() && (body[after] == ' ' || body[after] == '\t')) ++after;
      if (body.substr(after, 2) == "\r\n") break;
      end = body.find(delimiter, end + 1);
    }
    if (end == std::string_view::npos) {
      out.error = "the body ends inside the part '" + part.name + "' (no closing boundary)";
      return out;
    }
    part.data = body.substr(pos, end - pos);
    out.parts.push_back(std::move(part));
    pos = end + delimiter.size();
  }
}

}  // namespace penumbra::server
