// Flags and environment variables of `penumbra serve`, durations and sizes, loopback detection.
#include "server/server_config.h"

#include "server/loopback.h"

#include <gtest/gtest.h>

#include <map>

namespace penumbra::test {
namespace {

using namespace penumbra::server;

ConfigParse parse(std::vector<std::string> args, std::map<std::string, std::string> env = {}) {
  return parse_server_config(args, [&](const char* name) -> const char* {
    const auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  });
}

TEST(ServerConfig, DefaultsAreDocumented) {
  const auto p = parse({});
  ASSERT_TRUE(p.config);
  EXPECT_EQ(p.config->host, "127.0.0.1");
  EXPECT_EQ(p.config->port, 8080);
  EXPECT_EQ(p.config->workers, 1);
  EXPECT_EQ(p.config->max_queue, 64);
  EXPECT_EQ(p.config->max_body_bytes, 16u << 20);
  EXPECT_EQ(p.config->retention_seconds, 24 * 3600.0);
  EXPECT_EQ(p.config->max_render_seconds, 600.0);
  EXPECT_TRUE(p.config->token.empty());
}

TEST(ServerConfig, FlagsOverrideEnvironmentOverrideDefaults) {
  const auto p = parse({"--port", "9000", "--max-body=1M"}, {{"PENUMBRA_PORT", "7000"},
                                                             {"PENUMBRA_WORKERS", "3"},
                                                             {"PENUMBRA_TOKEN", "s3cret"},
                                                             {"PENUMBRA_RETENTION", "15m"},
                                                             {"PENUMBRA_DATA_DIR", "/data"}});
  ASSERT_TRUE(p.config) << p.error;
  EXPECT_EQ(p.config->port, 9000);
  EXPECT_EQ(p.config->workers, 3);
  EXPECT_EQ(p.config->token, "s3cret");
  EXPECT_EQ(p.config->retention_seconds, 900.0);
  EXPECT_EQ(p.config->data_dir, "/data");
  EXPECT_EQ(p.config->max_body_bytes, 1u << 20);
}

TEST(ServerConfig, RejectsBadValuesNamingTheFlag) {
  EXPECT_NE(parse({"--port", "70000"}).error.find("--port"), std::string::npos);
  EXPECT_NE(parse({"--workers", "0"}).error.find("--workers"), std::string::npos);
  EXPECT_NE(parse({"--retention", "soon"}).error.find("--retention"), std::string::npos);
  EXPECT_NE(parse({"--bogus"}).error.find("unknown option"), std::string::npos);
  EXPECT_NE(parse({"--port"}).error.find("missing value"), std::string::npos);
  EXPECT_NE(parse({}, {{"PENUMBRA_MAX_SPP", "x"}}).error.find("PENUMBRA_MAX_SPP"),
            std::string::npos);
  EXPECT_TRUE(parse({"--help"}).help);
}

TEST(ServerConfig, EveryFlagIsInTheUsage) {
  const std::string usage = serve_usage();
  for (const char* flag : {"--host",
                           "--port",
                           "--data-dir",
                           "--workers",
                           "--render-threads",
                           "--max-queue",
                           "--max-body",
                           "--max-pixels",
                           "--max-spp",
                           "--max-triangles",
                           "--max-render-time",
                           "--retention",
                           "--token",
                           "--insecure",
                           "--http-threads",
                           "--read-timeout",
                           "--write-timeout",
                           "--keep-alive",
                           "--keep-alive-requests",
                           "--drain",
                           "--access-log"}) {
    EXPECT_NE(usage.find(flag), std::string::npos) << flag;
  }
}

TEST(ServerConfig, DurationsAndSizes) {
  EXPECT_EQ(parse_duration("90"), 90.0);
  EXPECT_EQ(parse_duration("90s"), 90.0);
  EXPECT_EQ(parse_duration("15m"), 900.0);
  EXPECT_EQ(parse_duration("24h"), 86400.0);
  EXPECT_EQ(parse_duration("7d"), 7 * 86400.0);
  EXPECT_EQ(parse_duration("250ms"), 0.25);
  EXPECT_FALSE(parse_duration("-1s"));
  EXPECT_FALSE(parse_duration("abc"));
  EXPECT_EQ(parse_byte_size("512k"), 512u << 10);
  EXPECT_EQ(parse_byte_size("16M"), 16u << 20);
  EXPECT_EQ(parse_byte_size("1000"), 1000u);
  EXPECT_FALSE(parse_byte_size("1.5M"));
}

TEST(ServerConfig, Loopback) {
  EXPECT_TRUE(is_loopback_host("127.0.0.1"));
  EXPECT_TRUE(is_loopback_host("127.1.2.3"));
  EXPECT_TRUE(is_loopback_host("::1"));
  EXPECT_TRUE(is_loopback_host("localhost"));
  EXPECT_FALSE(is_loopback_host("0.0.0.0"));
  EXPECT_FALSE(is_loopback_host("::"));
  EXPECT_FALSE(is_loopback_host("192.168.1.5"));
  // Decided on resolved addresses, not on the text: a name that starts like a loopback address
  // but does not resolve to one (.test never resolves, RFC 6761) is not loopback.
  EXPECT_FALSE(is_loopback_host("127.example.test"));
  EXPECT_FALSE(is_loopback_host("127.0.0.1.example.test"));
  EXPECT_FALSE(is_loopback_host(""));
  EXPECT_TRUE(is_loopback_host("[::1]"));
  EXPECT_TRUE(is_loopback_host("::ffff:127.0.0.1"));
}

}  // namespace
}  // namespace penumbra::test
