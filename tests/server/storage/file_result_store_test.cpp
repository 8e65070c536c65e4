// Result files: whole or absent, readable while being removed, stale temporary files cleaned.
#include "server/storage/file_result_store.h"

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

}  // namespace
}  // namespace penumbra::test
