// FileBytes: a file mapped, not copied; errors before anything is mapped; a file that shrinks
// while mapped reads as zeros where it lost bytes and says so, instead of ending the process
// with SIGBUS; every other SIGBUS still does.
#include "renderer/io/file_bytes.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <vector>

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class FileBytesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_file_bytes_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }
  std::string error(const fs::path& path, int64_t max_bytes = 1 << 20) {
    try {
      FileBytes::map(path, max_bytes);
    } catch (const FileBytesError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

std::string pattern(size_t n) {
  std::string s(n, '\0');
  for (size_t i = 0; i < n; ++i) s[i] = char('a' + i % 23);
  return s;
}

TEST_F(FileBytesTest, MapsTheWholeFile) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  for (const size_t n : {size_t(1), page - 1, page, page + 1, 5 * page + 17}) {
    const std::string bytes = pattern(n);
    const FileBytes file = FileBytes::map(write("a.bin", bytes), 1 << 20);
    EXPECT_EQ(file.view(), bytes) << n;
    EXPECT_TRUE(file.intact());
  }
  EXPECT_TRUE(FileBytes::map(write("empty.bin", ""), 0).view().empty());
}

TEST_F(FileBytesTest, ErrorsBeforeMapping) {
  write("a.bin", "12345");
  EXPECT_EQ(error(dir_ / "a.bin", 5), "");
  EXPECT_EQ(error(dir_ / "a.bin", 4), "the file has 5 bytes; at most 4 are allowed");
  EXPECT_EQ(error(dir_ / "missing.bin"), "cannot open the file");
  EXPECT_EQ(error(dir_), "cannot read the file");  // a directory
}

TEST_F(FileBytesTest, MovedAndReleased) {
  const std::string bytes = pattern(10000);
  FileBytes a = FileBytes::map(write("a.bin", bytes), 1 << 20);
  FileBytes b = std::move(a);
  EXPECT_TRUE(a.view().empty());
  EXPECT_EQ(b.view(), bytes);
  FileBytes owned = std::string("short");  // within the string's own storage
  FileBytes moved = std::move(owned);
  EXPECT_EQ(moved.view(), "short");
  b.release();
  EXPECT_TRUE(b.view().empty());
  EXPECT_TRUE(b.intact());
}

TEST_F(FileBytesTest, ManyFilesAtOnceAreAllRead) {
  // More files than the guard has slots: those past it are read into memory.
  std::vector<FileBytes> files;
  for (int i = 0; i < 70; ++i) {
    const std::string name = std::to_string(i) + ".bin";
    files.push_back(FileBytes::map(write(name, pattern(100 + size_t(i))), 1 << 20));
  }
  for (int i = 0; i < 70; ++i) EXPECT_EQ(files[size_t(i)].view(), pattern(100 + size_t(i))) << i;
}

TEST_F(FileBytesTest, AFileThatShrinksReadsAsZerosAndSaysSo) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  const std::string bytes = pattern(6 * page);
  const fs::path path = write("a.bin", bytes);
  FileBytes file = FileBytes::map(path, 1 << 20);
  fs::resize_file(path, page + 10);  // as an exporter rewriting the file in place would
  // Reading every byte would raise SIGBUS past the file's new last page without the guard.
  const std::string_view view = file.view();
  ASSERT_EQ(view.size(), bytes.size());
  size_t zeros = 0;
  for (const char c : view) zeros += c == '\0';
  EXPECT_EQ(view.substr(0, page + 10), bytes.substr(0, page + 10));
  EXPECT_EQ(zeros, bytes.size() - (page + 10));
  EXPECT_FALSE(file.intact());
  file.release();
  EXPECT_FALSE(file.intact());  // remembered after release
  // The slot is free again and a new mapping starts intact.
  EXPECT_TRUE(FileBytes::map(write("b.bin", bytes), 1 << 20).intact());
}

TEST_F(FileBytesTest, OtherBusErrorsStillEndTheProcess) {
  FileBytes file = FileBytes::map(write("a.bin", "installs the guard"), 1 << 20);
  GTEST_FLAG_SET(death_test_style, "threadsafe");  // the test process has TBB threads
  // Killed by SIGBUS, or ended by a sanitizer whose handler was installed before ours (abort or
  // an error exit); returning from raise would fail the test ("failed to die").
  EXPECT_EXIT(raise(SIGBUS),
              [](int status) { return !WIFEXITED(status) || WEXITSTATUS(status) != 0; }, "");
}

}  // namespace
}  // namespace penumbra::test
