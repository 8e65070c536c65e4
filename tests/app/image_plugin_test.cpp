// OpenImageIO is loaded only when a scene reads an image asset (renderer/io/oiio_module.h):
// rendering to PNG and EXR works without the plug-in, a scene with an environment map needs it
// and says which file could not be read and why, and the binary itself does not link it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/app/app_test_util.h"

namespace penumbra::test {
namespace {

// Points the plug-in search at a file that does not exist for the commands run in its scope.
class NoPlugin {
 public:
  NoPlugin() { ::setenv("PENUMBRA_OIIO_MODULE", "/nonexistent/libpenumbra_oiio.so", 1); }
  ~NoPlugin() { ::unsetenv("PENUMBRA_OIIO_MODULE"); }
};

TEST(ImagePlugin, RendersPngAndExrWithoutIt) {
  SceneFolder folder;
  const NoPlugin no_plugin;
  for (const char* out : {"out.png", "out.exr"}) {
    const CommandResult r = run_penumbra(folder, std::string("render scene.json -q -o ") + out);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_GT(std::filesystem::file_size(folder.file(out)), 100u) << out;
  }
}

TEST(ImagePlugin, AnEnvironmentMapNeedsItAndTheErrorSaysSo) {
  SceneFolder folder;
  std::filesystem::copy_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/sky_sun.hdr",
                             folder.file("sky.hdr"));
  std::ofstream(folder.file("env.json")) << R"({"version": 1,
      "render": {"width": 8, "height": 8, "spp": 1},
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "environment": {"map": "sky.hdr"},
      "materials": {"white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}]})";
  {
    const NoPlugin no_plugin;
    const CommandResult r = run_penumbra(folder, "render env.json -q -o out.exr");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("sky.hdr"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("libpenumbra_oiio.so"), std::string::npos) << r.output;
  }
  // With the plug-in where the build puts it, the same scene renders.
  const CommandResult r = run_penumbra(folder, "render env.json -q -o out.exr");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// The executable's dynamic section names no OpenImageIO library: starting it costs none of
// OpenImageIO's ~250 dependencies.
TEST(ImagePlugin, TheBinaryDoesNotLinkOpenImageIo) {
  std::ifstream in(PENUMBRA_BINARY, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 0u);
  EXPECT_EQ(bytes.find("libOpenImageIO"), std::string::npos);
}

}  // namespace
}  // namespace penumbra::test
