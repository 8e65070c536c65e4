// `penumbra render --denoise` end to end through the binary: the denoised image, the image as
// rendered kept as the "noisy" layer (bit for bit the render without --denoise), the guide
// layers not written unless asked for; and without Open Image Denoise, a warning and the image
// as rendered, never a failure.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "tests/app/app_test_util.h"
#include "tests/app/exr_test_util.h"
#include "tests/oidn_test_util.h"

namespace penumbra::test {
namespace {

TEST(RenderDenoise, DenoisedImageWithTheNoisyOneKept) {
  PENUMBRA_REQUIRE_OIDN_OR_SKIP();
  SceneFolder folder;
  CommandResult r = run_penumbra(folder, "render scene.json --spp 4 -q -o plain.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_penumbra(folder, "render scene.json --spp 4 --denoise -q -o d.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("denoised in"), std::string::npos) << r.output;
  // The guides are not written unless asked for: beauty and noisy only.
  EXPECT_EQ(exr_channels(folder.file("d.exr")),
            (std::set<std::string>{"R", "G", "B", "noisy.R", "noisy.G", "noisy.B"}));
  // The noisy layer is the render without --denoise, bit for bit; the image is not.
  const auto noisy = read_exr_channel(folder.file("d.exr"), "noisy.G");
  const auto plain = read_exr_channel(folder.file("plain.exr"), "G");
  const auto denoised = read_exr_channel(folder.file("d.exr"), "G");
  EXPECT_EQ(noisy, plain);
  EXPECT_NE(denoised, plain);
  for (float v : denoised) ASSERT_TRUE(std::isfinite(v) && v >= 0.f);
  // Asked-for layers stay; PNG output writes the noisy image beside the denoised one.
  r = run_penumbra(folder, "render scene.json --spp 4 --denoise --aov albedo -q -o a.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(exr_channels(folder.file("a.exr")),
            (std::set<std::string>{"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "noisy.R",
                                   "noisy.G", "noisy.B"}));
  r = run_penumbra(folder, "render scene.json --spp 4 --denoise true -q -o p.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(folder.file("p.noisy.png")));
  EXPECT_FALSE(std::filesystem::exists(folder.file("p.normal.png")));
}

TEST(RenderDenoise, WithoutOpenImageDenoiseTheImageIsKeptWithAWarning) {
  SceneFolder folder;
  const std::string command = "cd " + folder.path().string() +
                              " && PENUMBRA_OIDN_DIR=/nonexistent " + PENUMBRA_BINARY +
                              " render scene.json --spp 2 --denoise -q -o missing.exr 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
  const int status = ::pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << output;
  EXPECT_NE(output.find("warning: the image is not denoised"), std::string::npos) << output;
  EXPECT_NE(output.find("install-oidn"), std::string::npos) << output;
  EXPECT_EQ(exr_channels(folder.file("missing.exr")), (std::set<std::string>{"R", "G", "B"}));
}

TEST(RenderDenoise, TheFieldAndTheFlagAreChecked) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "render scene.json --denoise=maybe -q -o x.exr");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--denoise (/render/denoise): must be true or false"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace penumbra::test
