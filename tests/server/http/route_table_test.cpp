// Route templates (metric labels, 405 answers), found without std::regex.
#include "server/http/route_table.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using namespace penumbra::server;

TEST(Routes, TemplatesBoundTheMetricLabels) {
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567"), "/v1/jobs/{id}");
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567/result"), "/v1/jobs/{id}/result");
  EXPECT_EQ(route_template("/v1/jobs/../../etc/passwd"), "other");
  EXPECT_EQ(route_template("/anything"), "other");
  EXPECT_EQ(route_template("/v1/jobs"), "/v1/jobs");
  EXPECT_EQ(route_template("/healthz"), "/healthz");
  EXPECT_EQ(route_template("/v1/jobs/0123456789ABCDEF01234567"), "other") << "ids are lower case";
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef0123456"), "other") << "23 digits";
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef012345678"), "other") << "25 digits";
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567/"), "other");
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567/result/x"), "other");
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567/events"), "/v1/jobs/{id}/events");
  EXPECT_EQ(route_template("/v1/jobs/0123456789abcdef01234567/events/"), "other");
  EXPECT_EQ(route_template("/v1/jobs/"), "other");
  EXPECT_EQ(route_template("/v1/workers"), "/v1/workers");
  EXPECT_EQ(route_template("/v1/workers/"), "other");
}

TEST(Routes, AllowedMethodsForA405) {
  EXPECT_EQ(allowed_methods("/v1/jobs/{id}"), (std::vector<std::string>{"GET", "HEAD", "DELETE"}));
  EXPECT_EQ(allowed_methods("/v1/render"), (std::vector<std::string>{"POST"}));
}

}  // namespace
}  // namespace penumbra::test
