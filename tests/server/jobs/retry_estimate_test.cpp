// Retry-After for a full queue: the soonest end among running renders, else the observed average
// over the workers, else 1 s; never a fixed time per queued job.
#include "server/jobs/retry_estimate.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using server::queue_retry_after_seconds;

TEST(RetryEstimate, NothingObservedYetIsOneSecond) {
  EXPECT_EQ(queue_retry_after_seconds({}, 0, 1), 1.0);
  EXPECT_EQ(queue_retry_after_seconds({{0.0, 0.0}}, 0, 1), 1.0);  // started, no progress yet
}

TEST(RetryEstimate, FastJobsGiveTheMinimum) {
  // Issue 15: jobs of 0.02 s, 64 queued, answered Retry-After: 320.
  EXPECT_EQ(queue_retry_after_seconds({}, 0.02, 1), 1.0);
}

TEST(RetryEstimate, TheSoonestRunningJobDecides) {
  EXPECT_DOUBLE_EQ(queue_retry_after_seconds({{0.5, 40.0}, {0.9, 7.0}}, 100.0, 2), 7.0);
}

TEST(RetryEstimate, TheAverageIsSharedByTheWorkers) {
  EXPECT_DOUBLE_EQ(queue_retry_after_seconds({}, 30.0, 3), 10.0);
  EXPECT_DOUBLE_EQ(queue_retry_after_seconds({}, 1e9, 1), 3600.0);
}

}  // namespace
}  // namespace penumbra::test
