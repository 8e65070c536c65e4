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

constexpr int kSeqBits = 48;

std::string run_order_page_token(int priority, int64_t seq) {
  return page_token((int64_t(priority + 1000) << kSeqBits) | (seq & ((int64_t(1) << kSeqBits) - 1)));
}

std::pair<int, int64_t> run_order_from_token(int64_t token) {
  return {int(token >> kSeqBits) - 1000, token & ((int64_t(1) << kSeqBits) - 1)};
}

}  // namespace penumbra::server
