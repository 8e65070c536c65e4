// Result files: whole or absent, readable while being removed, stale temporary files cleaned.
#include "server/storage/file_result_store.h"
#include "server/storage/result_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/server/test_support.h"

namespace penumbra::test {
namespace {

const std::string kId = "0123456789abcdef01234567";

std::string read_all(std::istream& in) {
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(FileResultStore, WriteOpenRemove) {
  TempDir dir;
  server::FileResultStore files(dir.path());
  EXPECT_FALSE(files.open(kId, "png"));
  files.write(kId, "png", {'p', 'n', 'g'});
  files.write(kId, "exr", {'e', 'x', 'r', '!'});
  const auto png = files.open(kId, "png");
  ASSERT_TRUE(png);
  EXPECT_EQ(png->size, 3u);
  EXPECT_EQ(read_all(*png->stream), "png");
  EXPECT_FALSE(std::filesystem::exists(files.path(kId, "png") + ".tmp"));
  const auto exr = files.open(kId, "exr");
  files.remove(kId);
  EXPECT_FALSE(files.open(kId, "png"));
  EXPECT_FALSE(files.open(kId, "exr"));
  ASSERT_TRUE(exr);
  EXPECT_EQ(read_all(*exr->stream), "exr!") << "an open result stays readable after removal";
  EXPECT_NO_THROW(files.remove(kId)) << "removing what is gone is fine";
}

TEST(FileResultStore, StaleTemporaryFilesAreRemovedAtStartup) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() + "/results");
  const std::string stale = dir.path() + "/results/" + kId + ".png.tmp";
  std::ofstream(stale) << "half a file";
  server::FileResultStore files(dir.path());
  EXPECT_FALSE(std::filesystem::exists(stale));
}

// An animation's frames live in one folder per job (DIR/results/<id>.frames/), go with the job,
// and their stale temporary files are cleaned at startup too.
TEST(FileResultStore, FramesLiveInTheJobsFolder) {
  TempDir dir;
  {
    server::FileResultStore files(dir.path());
    files.write(kId, server::frame_result_key(17, "png"), {'1', '7'});
    files.write(kId, server::frame_result_key(-2, "albedo.exr"), {'a'});
    EXPECT_EQ(files.path(kId, server::frame_result_key(17, "png")),
              dir.path() + "/results/" + kId + ".frames/17.png");
    const auto f17 = files.open(kId, "frames/17.png");
    ASSERT_TRUE(f17);
    EXPECT_EQ(read_all(*f17->stream), "17");
    EXPECT_TRUE(files.open(kId, "frames/-2.albedo.exr"));
    EXPECT_FALSE(files.open(kId, "frames/18.png"));
    std::ofstream(files.frames_dir(kId) + "/18.png.tmp") << "half a frame";
  }
  server::FileResultStore files(dir.path());
  EXPECT_FALSE(std::filesystem::exists(files.frames_dir(kId) + "/18.png.tmp"));
  EXPECT_TRUE(files.open(kId, "frames/17.png"));
  files.remove(kId);
  EXPECT_FALSE(std::filesystem::exists(files.frames_dir(kId)));
  EXPECT_FALSE(files.open(kId, "frames/17.png"));
}

}  // namespace
}  // namespace penumbra::test
