// The farm's flags (--store, --role, leases) and the URL redaction of its log lines. The farm
// itself runs against a real PostgreSQL in tests/farm/farm_test.py (ctest label "farm").
#include <gtest/gtest.h>

#include <map>

#include "server/farm/pg_connection.h"
#include "server/server_config.h"

namespace penumbra::test {
namespace {

using namespace penumbra::server;

ConfigParse parse(std::vector<std::string> args, std::map<std::string, std::string> env = {}) {
  return parse_server_config(args, [&](const char* name) -> const char* {
    const auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  });
}

TEST(FarmConfig, DefaultIsOneNodeOnSqlite) {
  const auto p = parse({});
  ASSERT_TRUE(p.config);
  EXPECT_FALSE(p.config->farm());
  EXPECT_EQ(p.config->role, "all");
  EXPECT_EQ(p.config->lease_seconds, 30.0);
  EXPECT_EQ(p.config->heartbeat_seconds, 5.0);
  EXPECT_EQ(p.config->max_attempts, 3);
}

TEST(FarmConfig, PostgresStoreAndRoles) {
  for (const char* role : {"api", "worker", "all"}) {
    const auto p = parse({"--store", "postgres://u:pw@db:5432/farm", "--role", role});
    ASSERT_TRUE(p.config) << p.error;
    EXPECT_TRUE(p.config->farm());
    EXPECT_EQ(p.config->role, role);
    EXPECT_EQ(p.config->renders(), std::string(role) != "api");
  }
  const auto env = parse({}, {{"PENUMBRA_STORE", "postgresql://db/farm"}, {"PENUMBRA_ROLE", "api"}});
  ASSERT_TRUE(env.config) << env.error;
  EXPECT_EQ(env.config->store, "postgresql://db/farm");
  EXPECT_FALSE(env.config->renders());
}

TEST(FarmConfig, RefusesWhatCannotWork) {
  // A role without a shared store: the workers would have nothing to claim from.
  EXPECT_FALSE(parse({"--role", "worker"}).config);
  EXPECT_FALSE(parse({"--role", "api"}).config);
  EXPECT_FALSE(parse({"--store", "postgres://db/x", "--role", "everything"}).config);
  EXPECT_FALSE(parse({"--store", "mysql://db/x"}).config);
  // The error never echoes the URL (it may hold a password).
  const auto bad = parse({"--store", "mysql://u:secret@db/x"});
  EXPECT_EQ(bad.error.find("secret"), std::string::npos) << bad.error;
  // One late heartbeat must not lose the lease: heartbeat <= lease / 2.
  EXPECT_FALSE(parse({"--store", "postgres://db/x", "--lease-seconds", "4", "--heartbeat", "3"}).config);
  EXPECT_TRUE(parse({"--store", "postgres://db/x", "--lease-seconds", "4", "--heartbeat", "2"}).config);
  EXPECT_FALSE(parse({"--store", "postgres://db/x", "--max-attempts", "0"}).config);
  EXPECT_TRUE(parse({"--store", "sqlite"}).config);
}

TEST(FarmConfig, RedactsPasswordsInUrls) {
  EXPECT_EQ(redact_url("postgres://user:pa55@db:5432/farm"), "postgres://user:***@db:5432/farm");
  EXPECT_EQ(redact_url("postgres://user@db/farm"), "postgres://user@db/farm");
  EXPECT_EQ(redact_url("postgres://db:5432/farm"), "postgres://db:5432/farm");
  EXPECT_EQ(redact_url("postgresql:///farm?host=/run"), "postgresql:///farm?host=/run");
}

}  // namespace
}  // namespace penumbra::test
