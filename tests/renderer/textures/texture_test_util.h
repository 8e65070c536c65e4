#pragma once
// Writing small images for texture tests, through OpenImageIO.
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/textures/texture_image.h"

namespace penumbra::test {

// Writes `values` (width * height * channels, rows from the top) to `path`, stored as `type`
// (UINT8 values are given in [0, 1] and quantised by OpenImageIO). Colour is stored as given,
// not divided by alpha (OpenImageIO's default for PNG): the readers take stored values.
inline void write_test_image(const std::string& path, int width, int height, int channels,
                             const std::vector<float>& values,
                             OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error("no writer for " + path);
  OIIO::ImageSpec spec(width, height, channels, type);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, values.data()) || !out->close())
    throw std::runtime_error("cannot write " + path + ": " + out->geterror());
}

// A fresh empty folder under the system's temporary directory, removed by the destructor.
class TempFolder {
 public:
  explicit TempFolder(const std::string& name)
      : path_(std::filesystem::temp_directory_path() / ("penumbra_test_" + name)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempFolder() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace penumbra::test
