#pragma once
// Shared by the in-process and the end-to-end server tests (header-only, as only *_test.cpp
// files are compiled): a temporary directory and small valid scenes.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

namespace penumbra::test {

using Json = nlohmann::json;

// A fresh directory under the system temp dir, removed at destruction.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = (std::filesystem::temp_directory_path() /
             ("penumbra-server-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd())))
                .string();
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A valid scene (the Cornell box of scenes/) at a tiny size.
inline Json tiny_scene(int width = 16, int height = 16, int spp = 2) {
  Json scene =
      Json::parse(read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell_box.json"));
  scene["render"]["width"] = width;
  scene["render"]["height"] = height;
  scene["render"]["spp"] = spp;
  return scene;
}

// A render that keeps one worker busy for many seconds (to be cancelled or interrupted).
inline Json long_scene() { return tiny_scene(64, 64, 1 << 16); }

}  // namespace penumbra::test
