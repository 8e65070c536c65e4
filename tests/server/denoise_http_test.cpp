// render.denoise through the real binary over HTTP: the result is the denoised image, the image
// as rendered is ?layer=noisy (and "Noisy Image" in Blender's layout), the job's stats say so;
// with Open Image Denoise missing the job still succeeds with the image as rendered and says why.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "server_process.h"
#include "tests/oidn_test_util.h"

namespace penumbra::test {
namespace {

TEST(DenoiseHttp, DenoisedResultWithTheNoisyLayer) {
  PENUMBRA_REQUIRE_OIDN_OR_SKIP();
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  Json scene = tiny_scene(24, 16, 4);
  scene["render"]["denoise"] = true;
  const std::string id = submit(*c, scene);
  const Json done = wait_for_state(*c, id, {"succeeded", "failed"});
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["stats"]["denoised"], true) << done.dump();
  EXPECT_FALSE(done["stats"].contains("denoise_error"));
  const std::string base = "/v1/jobs/" + id + "/result";
  auto beauty = c->Get((base + "?format=exr").c_str());
  auto noisy = c->Get((base + "?layer=noisy&format=exr").c_str());
  ASSERT_EQ(beauty->status, 200);
  ASSERT_EQ(noisy->status, 200) << noisy->body;
  EXPECT_NE(beauty->body, noisy->body);
  EXPECT_NE(beauty->body.find(std::string("noisy.R\0", 8)), std::string::npos);
  EXPECT_EQ(beauty->body.find(std::string("albedo.R\0", 9)), std::string::npos);  // guides dropped
  auto png = c->Get((base + "?layer=noisy").c_str());
  EXPECT_EQ(png->status, 200);
  auto blender = c->Get((base + "?layout=blender").c_str());
  ASSERT_EQ(blender->status, 200);
  EXPECT_NE(blender->body.find("ViewLayer.Noisy Image.R"), std::string::npos);
  // The same scene without denoise: its image is the noisy layer's, and it has no such layer.
  scene["render"]["denoise"] = false;
  const std::string plain = submit(*c, scene);
  ASSERT_EQ(wait_for_state(*c, plain, {"succeeded", "failed"})["state"], "succeeded");
  EXPECT_EQ(c->Get(("/v1/jobs/" + plain + "/result?layer=noisy").c_str())->status, 404);
}

TEST(DenoiseHttp, WithoutOpenImageDenoiseTheJobSucceedsAndSaysWhy) {
  TempDir dir;
  ServerProcess server(dir.path(), {}, {"PENUMBRA_OIDN_DIR=/nonexistent"});
  auto c = server.client();
  Json scene = tiny_scene(16, 8, 2);
  scene["render"]["denoise"] = true;
  const std::string id = submit(*c, scene);
  const Json done = wait_for_state(*c, id, {"succeeded", "failed"});
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["stats"]["denoised"], false);
  EXPECT_NE(done["stats"].value("denoise_error", std::string()).find("install-oidn"),
            std::string::npos)
      << done.dump();
  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result?layer=noisy").c_str())->status, 404);
  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result").c_str())->status, 200);
}

}  // namespace
}  // namespace penumbra::test
