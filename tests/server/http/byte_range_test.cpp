// Single byte ranges by RFC 9110 section 14: satisfiable ones cut to the file, unsatisfiable ones
// (start at or past the end, bytes=-0, any range of an empty file) refused, others ignored.
#include "server/http/byte_range.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using server::decide_range;
using server::RangeDecision;
using Kind = RangeDecision::Kind;

TEST(ByteRange, WithinTheFile) {
  const auto d = decide_range("bytes=0-99", 1000);
  EXPECT_EQ(d.kind, Kind::kPartial);
  EXPECT_EQ(d.first, 0u);
  EXPECT_EQ(d.last, 99u);
  const auto open = decide_range("bytes=990-", 1000);
  EXPECT_EQ(open.kind, Kind::kPartial);
  EXPECT_EQ(open.first, 990u);
  EXPECT_EQ(open.last, 999u);
}

TEST(ByteRange, StartAtTheBoundary) {
  EXPECT_EQ(decide_range("bytes=999-", 1000).kind, Kind::kPartial);  // last byte
  EXPECT_EQ(decide_range("bytes=1000-", 1000).kind, Kind::kUnsatisfiable);
  EXPECT_EQ(decide_range("bytes=99999999-", 1000).kind, Kind::kUnsatisfiable);
  EXPECT_EQ(decide_range("bytes=1000-2000", 1000).kind, Kind::kUnsatisfiable);
}

TEST(ByteRange, LastPastTheEndIsCut) {
  const auto d = decide_range("bytes=10-99999999999", 1000);
  EXPECT_EQ(d.kind, Kind::kPartial);
  EXPECT_EQ(d.last, 999u);
}

TEST(ByteRange, Suffixes) {
  EXPECT_EQ(decide_range("bytes=-0", 1000).kind, Kind::kUnsatisfiable);
  const auto one = decide_range("bytes=-1", 1000);
  EXPECT_EQ(one.kind, Kind::kPartial);
  EXPECT_EQ(one.first, 999u);
  const auto all = decide_range("bytes=-5000", 1000);
  EXPECT_EQ(all.kind, Kind::kPartial);
  EXPECT_EQ(all.first, 0u);
  EXPECT_EQ(all.last, 999u);
}

TEST(ByteRange, EmptyFileHasNoSatisfiableRange) {
  EXPECT_EQ(decide_range("bytes=0-", 0).kind, Kind::kUnsatisfiable);
  EXPECT_EQ(decide_range("bytes=-1", 0).kind, Kind::kUnsatisfiable);
}

TEST(ByteRange, OtherUnitsAndInvalidSyntaxAreIgnored) {
  EXPECT_EQ(decide_range(std::nullopt, 1000).kind, Kind::kWhole);
  EXPECT_EQ(decide_range("items=0-1", 1000).kind, Kind::kWhole);
  EXPECT_EQ(decide_range("bytes=5-2", 1000).kind, Kind::kWhole);
  EXPECT_EQ(decide_range("bytes=a-b", 1000).kind, Kind::kWhole);
  EXPECT_EQ(decide_range("bytes=12345678901234567890-", 1000).kind, Kind::kWhole);
  EXPECT_EQ(decide_range("BYTES=1-2", 1000).kind, Kind::kPartial);
}

}  // namespace
}  // namespace penumbra::test
