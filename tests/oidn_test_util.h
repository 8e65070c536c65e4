#pragma once
// Whether Open Image Denoise is installed beside the binary under test (scripts/install-oidn.sh
// puts it in <bin>/../lib/penumbra/oidn); tests of --denoise skip without it, except with
// PENUMBRA_REQUIRE_OIDN=1 (scripts/test.sh), where its absence is a failure.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace penumbra::test {

inline bool oidn_installed() {
  return std::filesystem::exists(std::filesystem::path(PENUMBRA_BINARY).parent_path() /
                                 "../lib/penumbra/oidn/libOpenImageDenoise.so.2");
}

inline bool oidn_required() {
  const char* required = std::getenv("PENUMBRA_REQUIRE_OIDN");
  return required && std::string(required) == "1";
}

}  // namespace penumbra::test

// In a test body: fails when OIDN is required but missing, skips when it is merely missing.
#define PENUMBRA_REQUIRE_OIDN_OR_SKIP()                                                     \
  do {                                                                                      \
    if (!::penumbra::test::oidn_installed()) {                                              \
      if (::penumbra::test::oidn_required()) FAIL() << "Open Image Denoise is not installed"; \
      GTEST_SKIP() << "Open Image Denoise is not installed (scripts/install-oidn.sh)";      \
    }                                                                                       \
  } while (0)
