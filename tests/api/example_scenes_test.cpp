// Every scene shipped in scenes/ loads without errors or warnings.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(ExampleScenes, AllLoadCleanly) {
  const std::filesystem::path dir = std::filesystem::path(PENUMBRA_SOURCE_DIR) / "scenes";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    ++count;
    const LoadResult r = load_scene_file(entry.path().string());
    EXPECT_TRUE(r.ok()) << entry.path() << "\n" << describe(r.errors);
    EXPECT_TRUE(r.warnings.empty()) << entry.path() << "\n" << describe(r.warnings);
    if (!r.ok()) continue;
    // "Renders in a few seconds": keep the examples small.
    const RenderSettings& s = r.request->settings;
    EXPECT_LE(s.width, 256) << entry.path();
    EXPECT_LE(s.height, 256) << entry.path();
    EXPECT_LE(s.spp, 64) << entry.path();
  }
  for (const char* required : {"cornell_box.json", "glass.json", "metals.json",
                               "depth_of_field.json", "motion_blur.json", "mesh.json", "textures.json",
                               "instances.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / required)) << required;
  EXPECT_GE(count, 7);
}

TEST(ExampleScenes, MissingFileIsAnErrorOnTheRoot) {
  const LoadResult r = load_scene_file("/nonexistent/scene.json");
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(has(r.errors, "", "cannot read file")) << describe(r.errors);
  const LoadResult dir = load_scene_file(PENUMBRA_SOURCE_DIR);
  EXPECT_TRUE(has(dir.errors, "", "cannot read file")) << describe(dir.errors);
}

// A scene file is mapped where it is a regular file and read as a stream where it is not: a
// pipe (`penumbra render <(make_scene) ...`) loads as the same scene.
TEST(ExampleScenes, SceneThroughAPipeLoadsAsTheFile) {
  const std::filesystem::path scene =
      std::filesystem::path(PENUMBRA_SOURCE_DIR) / "scenes" / "cornell_box.json";
  std::ostringstream text;
  text << std::ifstream(scene).rdbuf();
  std::string dir = (std::filesystem::temp_directory_path() / "penumbra_pipe_XXXXXX").string();
  ASSERT_NE(mkdtemp(dir.data()), nullptr);
  const std::string fifo = dir + "/scene.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // The writer waits at most two seconds for a reader (a loader that never opens the pipe must
  // fail this test, not hang it) and ignores a reader that leaves early (SIGPIPE).
  struct sigaction ignore {}, old {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ignore, &old);
  std::thread writer([&] {
    int fd = -1;
    for (int tries = 0; fd < 0 && tries < 200; ++tries) {
      fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // ENXIO until a reader opens it
      if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (fd < 0) return;
    fcntl(fd, F_SETFL, 0);
    const std::string bytes = text.str();
    for (size_t at = 0; at < bytes.size();) {
      const ssize_t n = write(fd, bytes.data() + at, bytes.size() - at);
      if (n <= 0) break;
      at += size_t(n);
    }
    close(fd);
  });
  const LoadResult piped = load_scene_file(fifo);
  writer.join();
  sigaction(SIGPIPE, &old, nullptr);
  std::filesystem::remove_all(dir);
  const LoadResult file = load_scene_file(scene.string());
  ASSERT_TRUE(piped.ok()) << describe(piped.errors);
  ASSERT_TRUE(file.ok()) << describe(file.errors);
  EXPECT_EQ(piped.request->settings.width, file.request->settings.width);
  EXPECT_EQ(piped.request->settings.spp, file.request->settings.spp);
  EXPECT_EQ(piped.request->scene.objects.size(), file.request->scene.objects.size());
}

}  // namespace
}  // namespace penumbra::test
