#include "server/http/paging.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace penumbra::server {
namespace {

bool all_of(const std::string& s, int (*pred)(int)) {
  return std::all_of(s.begin(), s.end(),
                     [pred](char c) { return pred(static_cast<unsigned char>(c)) != 0; });
}

}  // namespace

std::variant<ListQuery, Problem> parse_list_query(const ListParams& params) {
  ListQuery q;
  if (params.limit) {
    const std::string& v = *params.limit;
    // At most 4 digits, so stoi cannot overflow.
    const bool ok = !v.empty() && v.size() <= 4 && all_of(v, ::isdigit) && std::stoi(v) >= 1 &&
                    std::stoi(v) <= kMaxPageSize;
    if (!ok)
      return invalid_parameter("limit",
                               "must be an integer from 1 to " + std::to_string(kMaxPageSize));
    q.limit = std::stoi(v);
  }
  if (params.state) {
    q.state = job_state_from_string(*params.state);
    if (!q.state || *q.state == JobState::kDeleted)
      return invalid_parameter("state",
                               "must be one of queued, running, succeeded, failed, cancelled");
  }
  if (params.page_token && !params.page_token->empty() && (*params.page_token)[0] == 'p') {
    // A run-order token (state=queued): p<priority + 1000>-<seq>, both hex.
    const std::string& t = *params.page_token;
    const auto dash = t.find('-');
    const std::string p = t.substr(1, dash == std::string::npos ? 0 : dash - 1);
    const std::string s = dash == std::string::npos ? "" : t.substr(dash + 1);
    const bool ok = q.state == JobState::kQueued && !p.empty() && p.size() <= 4 &&
                    all_of(p, ::isxdigit) && !s.empty() && s.size() <= 15 && all_of(s, ::isxdigit);
    if (!ok) return invalid_parameter("page_token", "is not a token this server issued");
    q.run_after = std::make_pair(int(std::stol(p, nullptr, 16)) - 1000, int64_t(std::stoll(s, nullptr, 16)));
    return q;
  }
  if (params.page_token) {
    const std::string& t = *params.page_token;
    // 15 hex digits at most: the value fits an int64_t.
    if (t.empty() || t.size() > 15 || !all_of(t, ::isxdigit))
      return invalid_parameter("page_token", "is not a token this server issued");
    q.before_seq = std::stoll(t, nullptr, 16);
  }
  return q;
}

std::string page_token(int64_t last_seq_of_page) {
  char token[32];
  std::snprintf(token, sizeof token, "%llx", static_cast<unsigned long long>(last_seq_of_page));
  return token;
}

std::string run_order_page_token(int priority, int64_t seq) {
  char token[48];
  std::snprintf(token, sizeof token, "p%x-%llx", unsigned(priority + 1000),
                static_cast<unsigned long long>(seq));
  return token;
}

}  // namespace penumbra::server
