#include "server/jobs/webhook_url.h"

#include <algorithm>
#include <cctype>

#include "server/text_util.h"

namespace penumbra::server {
namespace {

// A DNS name, an IPv4 literal, or (inside brackets, checked by the caller) an IPv6 literal.
bool valid_host(std::string_view h, bool v6) {
  if (h.empty() || h.size() > 253) return false;
  for (char c : h) {
    const bool ok = v6 ? (std::isxdigit(static_cast<unsigned char>(c)) || c == ':' || c == '.')
                       : (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.');
    if (!ok) return false;
  }
  return true;
}

std::optional<int> parse_port(std::string_view p) {
  if (p.empty() || p.size() > 5) return std::nullopt;
  int v = 0;
  for (char c : p) {
    if (c < '0' || c > '9') return std::nullopt;
    v = v * 10 + (c - '0');
  }
  if (v < 1 || v > 65535) return std::nullopt;
  return v;
}

// "host", "host:port", "[v6]", "[v6]:port" -> host and port (0 = none); false when malformed.
bool split_host_port(std::string_view authority, std::string& host, int& port) {
  port = 0;
  std::string_view rest;
  bool v6 = false;
  if (!authority.empty() && authority.front() == '[') {
    const auto close = authority.find(']');
    if (close == std::string_view::npos) return false;
    host = ascii_lower(std::string(authority.substr(1, close - 1)));
    rest = authority.substr(close + 1);
    v6 = true;
  } else {
    const auto colon = authority.find(':');
    host = ascii_lower(std::string(authority.substr(0, colon)));
    rest = colon == std::string_view::npos ? std::string_view() : authority.substr(colon);
  }
  if (!valid_host(host, v6)) return false;
  if (rest.empty()) return true;
  if (rest.front() != ':') return false;
  const auto p = parse_port(rest.substr(1));
  if (!p) return false;
  port = *p;
  return true;
}

}  // namespace

std::string WebhookUrl::origin() const {
  const std::string h = host.find(':') != std::string::npos ? "[" + host + "]" : host;
  return std::string(https ? "https://" : "http://") + h + ":" + std::to_string(port);
}

ParsedWebhookUrl parse_webhook_url(std::string_view text) {
  ParsedWebhookUrl out;
  if (text.size() > 2048) {
    out.error = "must be at most 2048 characters";
    return out;
  }
  for (char c : text) {
    if (static_cast<unsigned char>(c) <= 0x20 || static_cast<unsigned char>(c) >= 0x7f) {
      out.error = "must be an ASCII URL without spaces or control characters";
      return out;
    }
  }
  WebhookUrl url;
  std::string_view rest;
  const std::string head = ascii_lower(std::string(text.substr(0, 8)));
  if (head.rfind("https://", 0) == 0) {
    url.https = true;
    rest = text.substr(8);
  } else if (head.rfind("http://", 0) == 0) {
    rest = text.substr(7);
  } else {
    out.error = "must start with http:// or https://";
    return out;
  }
  if (rest.find('#') != std::string_view::npos) {
    out.error = "must not have a fragment (#...)";
    return out;
  }
  const auto slash = rest.find_first_of("/?");
  const std::string_view authority = rest.substr(0, slash);
  if (authority.find('@') != std::string_view::npos) {
    out.error = "must not carry user information (user:password@)";
    return out;
  }
  if (!split_host_port(authority, url.host, url.port)) {
    out.error = "has no valid host[:port] after the scheme";
    return out;
  }
  if (url.port == 0) url.port = url.https ? 443 : 80;
  url.target = slash == std::string_view::npos ? "/" : std::string(rest.substr(slash));
  if (url.target.front() == '?') url.target = "/" + url.target;
  out.url = std::move(url);
  return out;
}

std::optional<std::vector<AllowedHost>> parse_allowed_hosts(const std::string& text,
                                                            std::string& error) {
  std::vector<AllowedHost> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    std::string item = text.substr(start, comma == std::string::npos ? std::string::npos
                                                                      : comma - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (!item.empty()) {
      AllowedHost h;
      if (!split_host_port(item, h.host, h.port)) {
        error = "'" + item + "' is not HOST or HOST:PORT";
        return std::nullopt;
      }
      out.push_back(std::move(h));
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

bool host_allowed(const WebhookUrl& url, const std::vector<AllowedHost>& allowed) {
  const int default_port = url.https ? 443 : 80;
  return std::any_of(allowed.begin(), allowed.end(), [&](const AllowedHost& a) {
    return a.host == url.host && (a.port == 0 ? url.port == default_port : a.port == url.port);
  });
}

}  // namespace penumbra::server
