// `penumbra serve` runs `penumbra-serve` beside the CLI binary (app/CMakeLists.txt): the CLI
// itself names none of the service's libraries, `serve` reaches the service through it (every
// other test in this folder starts the service that way), and without the service binary it
// says which file it could not run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/app/app_test_util.h"

namespace penumbra::test {
namespace {

TEST(ServeBinary, TheCliNamesNoLibraryOfTheService) {
  std::ifstream in(PENUMBRA_BINARY, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 0u);
  for (const char* library : {"libpq.so", "libssl.so", "libcrypto.so", "libsqlite3.so",
                              "libcpp-httplib.so"})
    EXPECT_EQ(bytes.find(library), std::string::npos) << library;
}

TEST(ServeBinary, ServeRunsTheServiceBinaryBesideIt) {
  const CommandResult r = run_command(std::string(PENUMBRA_BINARY) + " serve --help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("usage: penumbra serve"), std::string::npos) << r.output;
}

TEST(ServeBinary, WithoutTheServiceBinaryServeSaysWhichFileItCouldNotRun) {
  const SceneFolder folder;  // a scratch folder with the CLI alone in it
  std::filesystem::copy_file(PENUMBRA_BINARY, folder.file("penumbra"));
  const CommandResult r = run_command(folder.file("penumbra") + " serve --help");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(folder.file("penumbra-serve")), std::string::npos) << r.output;
}

}  // namespace
}  // namespace penumbra::test
