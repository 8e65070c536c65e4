// Route templates (metric labels, 405 answers), found without std::regex.
#include <gtest/gtest.h>

#include "server/http/route_table.h"

namespace penumbra::test {
namespace {

using namespace penumbra::server;

TEST(Routes, TemplatesBoundTheMetricLabels) {
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567"), "/v1/jobs/{id}");
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567/result"), "/v1/jobs/{id}/result");
  EXPECT_EQ(route_template("/v1/jobs/../../etc/passwd"), "other");
  EXPECT_EQ(route_template("/anything"), "other");
}

}  // namespace
}  // namespace penumbra::test
