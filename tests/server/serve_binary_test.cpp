// `penumbra serve` runs `penumbra-serve` beside the CLI binary (app/CMakeLists.txt): the CLI
// itself names none of the service's libraries, `serve` reaches the service through it (every
// other test in this folder starts the service that way), and without the service binary it
// says which file it could not run.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace penumbra::test {
namespace {

struct CommandOutcome {
  int exit_code = -1;
  std::string output;
};

CommandOutcome run(const std::string& command) {
  CommandOutcome r;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

TEST(ServeBinary, TheCliNamesNoLibraryOfTheService) {
  std::ifstream in(PENUMBRA_BINARY, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 0u);
  for (const char* library : {"libpq.so", "libssl.so", "libcrypto.so", "libsqlite3.so",
                              "libcpp-httplib.so"})
    EXPECT_EQ(bytes.find(library), std::string::npos) << library;
}

TEST(ServeBinary, ServeRunsTheServiceBinaryBesideIt) {
  const CommandOutcome r = run(std::string(PENUMBRA_BINARY) + " serve --help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("usage: penumbra serve"), std::string::npos) << r.output;
}

TEST(ServeBinary, WithoutTheServiceBinaryServeSaysWhichFileItCouldNotRun) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("penumbra-serve-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(PENUMBRA_BINARY, dir / "penumbra");
  const CommandOutcome r = run((dir / "penumbra").string() + " serve --help");
  std::filesystem::remove_all(dir);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "penumbra-serve").string()), std::string::npos) << r.output;
}

}  // namespace
}  // namespace penumbra::test
