// GET /v1/jobs query parameters at their boundaries, and page tokens that round-trip.
#include "server/http/paging.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using server::JobState;
using server::ListParams;
using server::ListQuery;
using server::Problem;

using Text = std::optional<std::string>;

std::optional<ListQuery> parse(Text limit, Text state = std::nullopt,
                               Text page_token = std::nullopt) {
  const auto r = server::parse_list_query(ListParams{limit, state, page_token});
  if (std::holds_alternative<Problem>(r)) return std::nullopt;
  return std::get<ListQuery>(r);
}

TEST(Paging, Defaults) {
  const auto q = parse(std::nullopt);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->limit, 20);
  EXPECT_FALSE(q->state);
  EXPECT_EQ(q->before_seq, 0);
}

TEST(Paging, LimitAtItsBoundaries) {
  EXPECT_EQ(parse("1")->limit, 1);
  EXPECT_EQ(parse("100")->limit, 100);
  for (const char* bad : {"0", "101", "", "-1", "1e2", "12345", "abc"})
    EXPECT_FALSE(parse(bad)) << bad;
  const Problem p =
      std::get<Problem>(server::parse_list_query(ListParams{"0", std::nullopt, std::nullopt}));
  EXPECT_EQ(p.status, 400);
  EXPECT_EQ(p.extensions["errors"][0]["parameter"], "limit");
}

TEST(Paging, StateFilter) {
  EXPECT_EQ(parse(std::nullopt, "running")->state, JobState::kRunning);
  EXPECT_FALSE(parse(std::nullopt, "deleted")) << "tombstones are not listed";
  EXPECT_FALSE(parse(std::nullopt, "RUNNING"));
}

TEST(Paging, TokensRoundTrip) {
  for (int64_t seq : {int64_t(1), int64_t(255), int64_t(1) << 40}) {
    const auto q = parse(std::nullopt, std::nullopt, server::page_token(seq));
    ASSERT_TRUE(q) << seq;
    EXPECT_EQ(q->before_seq, seq);
  }
  EXPECT_EQ(server::page_token(255), "ff");
  for (const char* bad : {"", "xyz", "1234567890abcdef"})
    EXPECT_FALSE(parse(std::nullopt, std::nullopt, bad)) << bad;
}

}  // namespace
}  // namespace penumbra::test
