// Header floods, long Accept headers and range sweeps (issue 15 items 1, 3, 7): each refused
// early and cheaply, probes unaffected, and the server's memory back near its baseline after.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <random>
#include <thread>

#include "hostile_support.h"

namespace penumbra::test {
namespace {

TEST(Floods, HeaderFloodsAreCutAndMemoryReturns) {
  TempDir dir;
  ServerProcess server(dir.path());
  const int port = server.port();
  for (int i = 0; i < 20; ++i) probe_ms(port, "/healthz");  // warm up
  const long before = rss_kib(server.pid());
  // 4 rounds of 32 parallel connections, each offering 100 MB of headers (issue 15: 4 such
  // requests took RSS from 142 MB to 739 MB, and it stayed there).
  std::atomic<int> refused{0};
  for (int round = 0; round < 4; ++round) {
    std::vector<std::thread> flooders;
    for (int t = 0; t < 32; ++t)
      flooders.emplace_back([&] {
        const int fd = connect_loopback(port);
        if (fd < 0) return;
        send_all(fd, "GET /healthz HTTP/1.1\r\nHost: x\r\n");
        const std::string line = "X-Flood: " + std::string(4000, 'f') + "\r\n";
        std::string chunk;
        while (chunk.size() < (1u << 20)) chunk += line;
        for (int mb = 0; mb < 100; ++mb)
          if (!send_all(fd, chunk)) break;  // the server closes after its 431
        std::string got;
        char buf[4096];
        pollfd p{fd, POLLIN, 0};
        while (::poll(&p, 1, 500) > 0) {
          const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
          if (n <= 0) break;
          got.append(buf, std::size_t(n));
        }
        if (raw_status(got) == 431 || got.empty()) ++refused;
        ::close(fd);
      });
    for (auto& t : flooders) t.join();
  }
  EXPECT_EQ(refused.load(), 4 * 32);
  EXPECT_LT(probe_ms(port, "/healthz"), 100.0);
  const long right_after = rss_kib(server.pid());
  // Connection threads idle for 10 s leave (ConnectionPool), and their stacks and buffers with
  // them.
  std::this_thread::sleep_for(std::chrono::seconds(11));
  const long after = rss_kib(server.pid());
  std::printf("[ figures ] header floods: RSS before %ld KiB, right after %ld KiB, 11 s later "
              "%ld KiB\n",
              before, right_after, after);
  EXPECT_LT(after - before, 8 * 1024) << "more than 8 MiB kept after the floods";
}

TEST(Floods, LongAcceptHeadersDoNotDelayProbes) {
  // Issue 15 item 1: eight parallel 8000-comma Accept headers delayed /healthz by 8.7 s.
  TempDir dir;
  ServerProcess server(dir.path());
  const int port = server.port();
  const std::string accept(8000, ',');
  std::atomic<bool> go{true};
  std::atomic<int> sent{0};
  std::vector<std::thread> attackers;
  for (int t = 0; t < 8; ++t)
    attackers.emplace_back([&] {
      while (go) {
        raw_request(port,
                    "GET /v1/jobs/0123456789abcdef01234567/result HTTP/1.1\r\nHost: x\r\n"
                    "Connection: close\r\nAccept: " +
                        accept + "\r\n\r\n",
                    1000);
        ++sent;
      }
    });
  std::vector<double> probes;
  for (int i = 0; i < 30; ++i) {
    probes.push_back(probe_ms(port, "/healthz"));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  go = false;
  for (auto& t : attackers) t.join();
  std::printf(
      "[ figures ] 8 clients sending 8000-comma Accept (%d requests): /healthz p50 %.2f "
      "ms max %.2f ms\n",
      sent.load(), percentile(probes, 0.5), percentile(probes, 1.0));
  EXPECT_LT(percentile(probes, 1.0), 100.0);
  EXPECT_GT(sent.load(), 100);
}

TEST(Floods, RangeSweepNeverLiesAboutLengths) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string id = submit(*c, tiny_scene(16, 16, 1));
  ASSERT_EQ(wait_for_state(*c, id, {"succeeded"})["state"], "succeeded");
  const std::size_t size = c->Get("/v1/jobs/" + id + "/result")->body.size();
  std::mt19937 rng(15);
  const std::vector<std::string> numbers = {"",
                                            "0",
                                            "1",
                                            std::to_string(size - 1),
                                            std::to_string(size),
                                            std::to_string(size + 1),
                                            "99999999",
                                            "18446744073709551615",
                                            "9223372036854775807",
                                            "-1",
                                            "a",
                                            " 3"};
  int served = 0;
  for (int i = 0; i < 300; ++i) {
    const std::string range =
        "bytes=" + numbers[rng() % numbers.size()] + "-" + numbers[rng() % numbers.size()];
    auto res = c->Get("/v1/jobs/" + id + "/result", httplib::Headers{{"Range", range}});
    ASSERT_TRUE(res) << range;
    ASSERT_LT(res->status, 500) << range;
    if (res->status == 206) {
      ++served;
      EXPECT_LE(res->body.size(), size) << range;
      EXPECT_FALSE(res->get_header_value("Content-Range").empty()) << range;
    } else if (res->status == 200) {
      EXPECT_EQ(res->body.size(), size) << range;
    } else {
      EXPECT_EQ(res->status, 416) << range;
    }
  }
  EXPECT_GT(served, 0);
}

}  // namespace
}  // namespace penumbra::test
