#pragma once
// Helpers of the app tests: a scratch folder holding a small valid scene, and a run of the built
// `penumbra` binary in it.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace penumbra::test {

// A fresh folder under the system temp dir holding scene.json; removed at destruction.
class SceneFolder {
 public:
  SceneFolder() {
    std::random_device random;
    path_ = std::filesystem::temp_directory_path() /
            ("penumbra-app-test-" + std::to_string(::getpid()) + "-" + std::to_string(random()));
    std::filesystem::create_directories(path_);
    std::ofstream(path_ / "scene.json") << R"({"version": 1,
      "render": {"width": 16, "height": 12, "spp": 2},
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "materials": {"white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white",
                   "emission": [1, 1, 1]}]})";
  }
  ~SceneFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  SceneFolder(const SceneFolder&) = delete;
  SceneFolder& operator=(const SceneFolder&) = delete;

  std::filesystem::path path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr, interleaved
};

// Runs `command` through the shell, its stderr into its stdout.
inline CommandResult run_command(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Runs `penumbra ARGS` inside `folder` through the shell: tests pass plain words and paths
// without spaces or quotes.
inline CommandResult run_penumbra(const SceneFolder& folder, const std::string& args) {
  return run_command("cd " + folder.path().string() + " && " + std::string(PENUMBRA_BINARY) +
                     " " + args);
}

}  // namespace penumbra::test
