#pragma once
// The query of GET /v1/jobs: limit, state and page_token (the opaque token is the hex
// sequence number of the last job of the previous page).
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "server/http/problem.h"
#include "server/storage/job_record.h"

namespace penumbra::server {

constexpr int kDefaultPageSize = 20;
constexpr int kMaxPageSize = 100;

struct ListParams {  // the raw query parameters, when present
  std::optional<std::string> limit, state, page_token;
};

struct ListQuery {
  int limit = kDefaultPageSize;
  std::optional<JobState> state;
  int64_t before_seq = 0;  // 0 = from the newest
};

// A 400 problem names the first bad parameter.
std::variant<ListQuery, Problem> parse_list_query(const ListParams& params);
std::string page_token(int64_t last_seq_of_page);
// ?state=queued lists in run order (priority, then seq): its token packs the run key of the last
// job of the page into the same hex form, (priority + 1000) << 48 | seq.
std::string run_order_page_token(int priority, int64_t seq);
// The run key (priority, seq) a token of run_order_page_token names.
std::pair<int, int64_t> run_order_from_token(int64_t token);

}  // namespace penumbra::server
