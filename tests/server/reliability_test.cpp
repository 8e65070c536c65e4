// Issue 15 against the real binary: bodies of any Content-Type curl sends up to the body limit,
// result ranges by RFC 9110, disk space checked before work is accepted, a time limit met and
// reported, Retry-After from observed durations.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <chrono>
#include <fstream>

#include "server_process.h"

namespace penumbra::test {
namespace {

using Clock = std::chrono::steady_clock;

// "2026-11-30T15:21:33.123Z" -> seconds since midnight (tests do not run across midnight
// often enough to matter; a job of seconds would then fail once).
double seconds_of_day(const Json& rfc3339) {
  const std::string t = rfc3339.get<std::string>();
  return std::stod(t.substr(11, 2)) * 3600 + std::stod(t.substr(14, 2)) * 60 +
         std::stod(t.substr(17, 6));
}

Json body_json(const httplib::Result& res) {
  return res ? Json::parse(res->body, nullptr, false) : Json();
}

TEST(Reliability, ReadmeCurlWorksForBodiesAboveTheFormLimit) {
  // curl --data-binary without -H sends application/x-www-form-urlencoded; the library refused
  // such bodies above 8192 bytes with an about:blank 413. scenes/mesh.json is 435 KB.
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string mesh = read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/mesh.json");
  ASSERT_GT(mesh.size(), 8192u);
  auto form = c->Post("/v1/jobs", mesh, "application/x-www-form-urlencoded");
  ASSERT_TRUE(form);
  EXPECT_EQ(form->status, 202) << form->body;
  auto json = c->Post("/v1/jobs", mesh, "application/json");
  ASSERT_TRUE(json);
  EXPECT_EQ(json->status, 202) << json->body;
  auto text = c->Post("/v1/jobs", mesh, "text/plain");
  ASSERT_TRUE(text);
  EXPECT_EQ(text->status, 415);
  const Json p = body_json(text);
  EXPECT_EQ(p["type"], "urn:penumbra:problem:unsupported-media-type");
  EXPECT_EQ(p["header"], "Content-Type");
  EXPECT_NE(p["detail"].get<std::string>().find("Content-Type: application/json"),
            std::string::npos);
}

TEST(Reliability, BodyLimitAtTheBoundaryWithTheFormContentType) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-body", "20000"});
  auto c = server.client();
  Json scene = tiny_scene(8, 8, 1);
  std::string body = scene.dump();
  body += std::string(20000 - body.size(), ' ');  // JSON allows trailing whitespace
  auto at = c->Post("/v1/jobs", body, "application/x-www-form-urlencoded");
  ASSERT_TRUE(at);
  EXPECT_EQ(at->status, 202) << at->body;
  auto over = c->Post("/v1/jobs", body + " ", "application/x-www-form-urlencoded");
  ASSERT_TRUE(over);
  EXPECT_EQ(over->status, 413);
  EXPECT_EQ(body_json(over)["type"], "urn:penumbra:problem:body-too-large");
}

TEST(Reliability, ResultRangesFollowRfc9110) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string id = submit(*c, tiny_scene(8, 8, 1));
  wait_for_state(*c, id, {"succeeded"});
  const std::string path = "/v1/jobs/" + id + "/result";
  auto whole = c->Get(path);
  ASSERT_TRUE(whole);
  ASSERT_EQ(whole->status, 200);
  const std::size_t size = whole->body.size();
  auto get_range = [&](const std::string& range) {
    return c->Get(path, httplib::Headers{{"Range", range}});
  };
  auto last = get_range("bytes=" + std::to_string(size - 1) + "-");
  ASSERT_TRUE(last);
  EXPECT_EQ(last->status, 206);
  EXPECT_EQ(last->body, whole->body.substr(size - 1));
  EXPECT_EQ(last->get_header_value("Content-Range"), "bytes " + std::to_string(size - 1) + "-" +
                                                         std::to_string(size - 1) + "/" +
                                                         std::to_string(size));
  for (const std::string r : {"bytes=" + std::to_string(size) + "-", std::string("bytes=99999999-"),
                              std::string("bytes=-0")}) {
    auto res = get_range(r);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 416) << r;
    EXPECT_EQ(res->get_header_value("Content-Range"), "bytes */" + std::to_string(size)) << r;
    EXPECT_EQ(body_json(res)["type"], "urn:penumbra:problem:range-not-satisfiable") << r;
  }
  auto cut = get_range("bytes=10-99999999");
  ASSERT_TRUE(cut);
  EXPECT_EQ(cut->status, 206);
  EXPECT_EQ(cut->body, whole->body.substr(10));
  auto suffix = get_range("bytes=-99999999");
  ASSERT_TRUE(suffix);
  EXPECT_EQ(suffix->status, 206);
  EXPECT_EQ(suffix->body, whole->body);
  // Range on a JSON route is ignored (RFC 9110 section 14.2), not applied to the document.
  auto job = c->Get("/v1/jobs/" + id, httplib::Headers{{"Range", "bytes=99999999-"}});
  ASSERT_TRUE(job);
  EXPECT_EQ(job->status, 200);
  EXPECT_TRUE(body_json(job).is_object());
}

TEST(Reliability, NoRoomIs507AndNotReady) {
  // --min-free-space above what the file system has: configuration, not a mock.
  TempDir dir;
  ServerProcess server(dir.path(), {"--min-free-space", "1000000G"});
  auto c = server.client();
  auto res = post_json(*c, "/v1/jobs", tiny_scene().dump());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 507) << res->body;
  const Json p = body_json(res);
  EXPECT_EQ(p["type"], "urn:penumbra:problem:insufficient-storage");
  EXPECT_GT(p["bytes_needed"].get<double>(), p["bytes_available"].get<double>());
  auto ready = c->Get("/readyz");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 503);
  EXPECT_EQ(body_json(ready)["type"], "urn:penumbra:problem:storage-low");
  auto health = c->Get("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);  // alive, only not ready
}

// A small tmpfs as the data directory (needs CAP_SYS_ADMIN; skipped without it).
class SmallDisk {
 public:
  explicit SmallDisk(const std::string& path, const char* size) : path_(path) {
    mounted_ =
        ::mount("tmpfs", path.c_str(), "tmpfs", 0, (std::string("size=") + size).c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }

 private:
  std::string path_;
  bool mounted_ = false;
};

void fill_file(const std::string& path, std::size_t bytes) {
  std::ofstream out(path, std::ios::binary);
  const std::string block(1 << 16, 'z');
  for (std::size_t done = 0; done < bytes && out; done += block.size())
    out.write(block.data(), block.size());
}

TEST(Reliability, AFullDiskRefusesWorkAndRecoversWhenSpaceFrees) {
  TempDir dir;
  SmallDisk disk(dir.path(), "24m");
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (not root)";
  ServerProcess server(dir.path(), {"--min-free-space", "4M"});
  auto c = server.client();
  // A 512 x 512 job needs about 5.3 MB at worst (16 + 4 bytes a pixel).
  const Json scene = tiny_scene(512, 512, 1);
  const std::string first = submit(*c, scene);
  wait_for_state(*c, first, {"succeeded"});
  fill_file(dir.path() + "/ballast", 16u << 20);  // leaves less than 5.3 + 4 MB
  auto full = post_json(*c, "/v1/jobs", scene.dump());
  ASSERT_TRUE(full);
  EXPECT_EQ(full->status, 507) << full->body;
  // A small job still fits.
  EXPECT_EQ(post_json(*c, "/v1/jobs", tiny_scene(8, 8, 1).dump())->status, 202);
  fill_file(dir.path() + "/ballast2", 64u << 20);  // the rest: the disk is full
  auto ready = c->Get("/readyz");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 503);
  auto tiny = post_json(*c, "/v1/jobs", tiny_scene(8, 8, 1).dump());
  ASSERT_TRUE(tiny);
  EXPECT_EQ(tiny->status, 507) << tiny->body;
  // DELETE of a finished job while the disk is full: never 500.
  auto del = c->Delete("/v1/jobs/" + first);
  ASSERT_TRUE(del);
  EXPECT_TRUE(del->status == 204 || del->status == 503) << del->status << " " << del->body;
  // Space frees: ready again and accepting within a second.
  std::filesystem::remove(dir.path() + "/ballast");
  std::filesystem::remove(dir.path() + "/ballast2");
  const auto start = Clock::now();
  EXPECT_EQ(c->Get("/readyz")->status, 200);
  const std::string again = submit(*c, scene);
  wait_for_state(*c, again, {"succeeded"});
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(20));
  EXPECT_EQ(c->Get("/v1/jobs/" + again + "/result")->status, 200);
}

TEST(Reliability, TimeLimitMetAndReported) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  Json scene = tiny_scene(256, 256, 1 << 16);
  scene["render"]["time_limit"] = 1.5;
  const std::string id = submit(*c, scene);
  const Json job = wait_for_state(*c, id, {"succeeded"});
  EXPECT_EQ(job["stopped_early"], "time_limit") << job.dump();
  EXPECT_GT(job["spp_reached"].get<double>(), 0.0);
  EXPECT_LT(job["spp_reached"].get<double>(), double(1 << 16));
  // From running to finished, images written: within the limit plus about a tile's time
  // (the issue measured 21.2-23.5 s for a 20 s limit).
  const double seconds = seconds_of_day(job["finished_at"]) - seconds_of_day(job["started_at"]);
  EXPECT_LT(seconds, 1.5 + 0.1) << job.dump();
  EXPECT_GT(seconds, 1.0) << job.dump();
  auto metrics = c->Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("penumbra_jobs_stopped_early_total{reason=\"time_limit\"} 1"),
            std::string::npos);
}

}  // namespace
}  // namespace penumbra::test
