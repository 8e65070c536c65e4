// A full disk on a small tmpfs (issue 15 item 5): work refused with 507 before anything is
// written, /readyz not ready, DELETE never 500, and recovery once space frees, with its time.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <chrono>
#include <cstdio>
#include <fstream>

#include "hostile_support.h"

namespace penumbra::test {
namespace {

using Clock = std::chrono::steady_clock;

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

TEST(DiskFull, RefusesWorkAndRecoversWhenSpaceFrees) {
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
  const double recovery = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf(
      "[ figures ] disk full on a 24 MB tmpfs: 507 and /readyz 503; after freeing space, "
      "ready and a 512x512 job accepted and rendered in %.2f s\n",
      recovery);
  EXPECT_LT(recovery, 20.0);
  EXPECT_EQ(c->Get("/v1/jobs/" + again + "/result")->status, 200);
}

}  // namespace
}  // namespace penumbra::test
