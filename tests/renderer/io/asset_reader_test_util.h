#pragma once
// What the image asset readers' tests share: a file's bytes, and the check that a broken file
// is refused with an ImageIoError naming it.
#include <gtest/gtest.h>

#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>

#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {

inline std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The call throws ImageIoError whose message names `name` and contains `reason`.
template <typename F>
void expect_refused_naming(F&& call, const std::string& name, const std::string& reason = "") {
  try {
    call();
    ADD_FAILURE() << name << " was accepted";
  } catch (const ImageIoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(name), std::string::npos) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
  }
}

// Each of `files` (bytes) written to `dir` and read: refused, with the file named.
inline void expect_files_refused(const TempFolder& dir, const std::string& extension,
                                 std::initializer_list<std::string> files) {
  int k = 0;
  for (const std::string& bytes : files) {
    const std::string path = dir.file("broken" + std::to_string(k++) + extension);
    SCOPED_TRACE(path);
    std::ofstream(path, std::ios::binary) << bytes;
    expect_refused_naming([&] { read_asset_image(path); }, path);
  }
}

}  // namespace penumbra::test
