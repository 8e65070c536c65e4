#pragma once
// Which webhook URLs a job may name: http or https only, no user info, no fragment, and a host
// (with port) on the operator's allow list (--webhook-allow-hosts). An empty list turns
// webhooks off, so the service cannot be turned against the network it runs in (SSRF) unless
// the operator says which receivers it may reach.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra::server {

struct WebhookUrl {
  bool https = false;
  std::string host;  // lowercase; an IPv6 literal without its brackets
  int port = 0;      // explicit or the scheme's default
  std::string target;  // path and query, "/" at least
  // "http://host:port" as cpp-httplib's Client takes it (IPv6 in brackets).
  std::string origin() const;
};

// The URL split, or an error message ("must start with http:// or https://").
struct ParsedWebhookUrl {
  std::optional<WebhookUrl> url;
  std::string error;
};
ParsedWebhookUrl parse_webhook_url(std::string_view text);

// One --webhook-allow-hosts entry: HOST (the scheme's default port only) or HOST:PORT;
// "[v6]:PORT" for IPv6. Hosts compare case-insensitively and exactly (no wildcards).
struct AllowedHost {
  std::string host;
  int port = 0;  // 0 = the URL scheme's default port (80 or 443)
};
// "host[:port],..." -> entries; nullopt and an error when one is malformed.
std::optional<std::vector<AllowedHost>> parse_allowed_hosts(const std::string& text,
                                                            std::string& error);
bool host_allowed(const WebhookUrl& url, const std::vector<AllowedHost>& allowed);

}  // namespace penumbra::server
