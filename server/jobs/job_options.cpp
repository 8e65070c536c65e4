#include "server/jobs/job_options.h"

#include <nlohmann/json.hpp>

#include "api/diagnostics.h"
#include "api/json_document.h"

namespace penumbra::server {
namespace {

using Json = api::Json;

void read_priority(const Json& v, SplitSubmission& out) {
  const std::string range =
      "must be an integer from " + std::to_string(kMinPriority) + " to " +
      std::to_string(kMaxPriority) + " (higher runs first)";
  if (!v.is_number_integer()) {
    out.errors.push_back({"/priority", range});
    return;
  }
  // Unsigned and signed 64-bit both fit in the comparison below as long long / unsigned.
  if (v.is_number_unsigned() ? v.get<uint64_t>() > uint64_t(kMaxPriority)
                             : (v.get<int64_t>() < kMinPriority || v.get<int64_t>() > kMaxPriority)) {
    out.errors.push_back({"/priority", range});
    return;
  }
  out.options.priority = int(v.get<int64_t>());
}

void read_notify(const Json& v, const std::vector<AllowedHost>& allowed, SplitSubmission& out) {
  if (!v.is_object()) {
    out.errors.push_back({"/notify", "must be an object {\"url\": ..., \"secret\": ...}"});
    return;
  }
  for (const auto& [key, value] : v.items())
    if (key != "url" && key != "secret")
      out.errors.push_back({api::child_pointer("/notify", key),
                            "unknown field " + api::quote_user_string(key) +
                                " (notify has url and secret)"});
  const auto url = v.find("url");
  if (url == v.end() || !url->is_string()) {
    out.errors.push_back({"/notify/url", "is required: the http(s) URL to POST the job to"});
  } else {
    const ParsedWebhookUrl parsed = parse_webhook_url(url->get_ref<const std::string&>());
    if (!parsed.url) {
      out.errors.push_back({"/notify/url", parsed.error});
    } else if (allowed.empty()) {
      out.errors.push_back({"/notify/url",
                            "webhooks are off on this server (the operator allows no hosts: "
                            "--webhook-allow-hosts)"});
    } else if (!host_allowed(*parsed.url, allowed)) {
      out.errors.push_back({"/notify/url", "host " + api::quote_user_string(parsed.url->host) +
                                               " port " + std::to_string(parsed.url->port) +
                                               " is not among the hosts webhooks may reach "
                                               "(--webhook-allow-hosts)"});
    } else {
      out.options.notify_url = url->get<std::string>();
    }
  }
  const auto secret = v.find("secret");
  if (secret == v.end() || !secret->is_string()) {
    out.errors.push_back({"/notify/secret",
                          "is required: the key the body's HMAC-SHA256 signature is made with"});
  } else {
    const std::string& s = secret->get_ref<const std::string&>();
    // The secret is never quoted back, not even in an error.
    if (s.size() < kMinSecretBytes || s.size() > kMaxSecretBytes)
      out.errors.push_back({"/notify/secret", "must be " + std::to_string(kMinSecretBytes) +
                                                  " to " + std::to_string(kMaxSecretBytes) +
                                                  " bytes long"});
    else
      out.options.notify_secret = s;
  }
  if (!out.errors.empty()) {
    out.options.notify_url.clear();
    out.options.notify_secret.clear();
  }
}

}  // namespace

SplitSubmission split_job_options(std::string_view body, const std::vector<AllowedHost>& allowed,
                                  int max_json_depth) {
  SplitSubmission out;
  // Most bodies name neither member: they go to the scene loader as they are, parsed once.
  // A member name written with escapes ("\u0070riority") is missed here and then refused by the
  // scene parser as an unknown field: never silently ignored.
  if (body.find("\"priority\"") == std::string_view::npos &&
      body.find("\"notify\"") == std::string_view::npos) {
    out.scene_text = std::string(body);
    return out;
  }
  api::Diagnostics diag;
  api::JsonDocument doc = api::parse_json_document(body, max_json_depth, diag);
  if (!doc.value || !doc.value->is_object() ||
      (!doc.value->contains("priority") && !doc.value->contains("notify"))) {
    out.scene_text = std::string(body);
    return out;
  }
  // Duplicate keys: the text is rewritten below and would keep only one of them, so they are
  // reported here (the scene loader never sees the original text).
  for (api::Diagnostic& d : diag.take_errors()) out.errors.push_back(std::move(d));
  Json& root = *doc.value;
  if (const auto p = root.find("priority"); p != root.end()) read_priority(*p, out);
  if (const auto n = root.find("notify"); n != root.end()) read_notify(*n, allowed, out);
  root.erase("priority");
  root.erase("notify");
  out.scene_text = root.dump(-1, ' ', false, Json::error_handler_t::replace);
  return out;
}

}  // namespace penumbra::server
