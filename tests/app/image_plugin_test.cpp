// OpenImageIO is loaded only when a scene reads an image asset of a format penumbra does not
// read itself (renderer/io/oiio_module.h, image_reader.cpp): rendering to PNG and EXR and reading
// an HDR environment map work without the plug-in, a map in another format needs it and says
// which file could not be read and why, and the binary itself does not link it.
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

// An environment map `name` in `folder` (scene env.json) of the given bytes.
void write_env_scene(const SceneFolder& folder, const std::string& map) {
  std::ofstream(folder.file("env.json")) << R"({"version": 1,
      "render": {"width": 8, "height": 8, "spp": 1},
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "environment": {"map": ")" + map + R"("},
      "materials": {"white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}]})";
}

// PNG, JPEG, Radiance HDR and plain EXR are read without OpenImageIO (image_reader.cpp).
TEST(ImagePlugin, AnHdrEnvironmentMapRendersWithoutIt) {
  SceneFolder folder;
  std::filesystem::copy_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/sky_sun.hdr",
                             folder.file("sky.hdr"));
  write_env_scene(folder, "sky.hdr");
  const NoPlugin no_plugin;
  const CommandResult r = run_penumbra(folder, "render env.json -q -o out.exr");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(ImagePlugin, AFormatOnlyOpenImageIoReadsNeedsItAndTheErrorSaysSo) {
  SceneFolder folder;
  // A binary PPM (Netpbm P6), 2 x 2 pixels: OpenImageIO reads it, penumbra's own readers do not.
  std::ofstream(folder.file("sky.ppm"), std::ios::binary)
      << std::string("P6\n2 2\n255\n") + std::string(12, '\x80');
  write_env_scene(folder, "sky.ppm");
  {
    const NoPlugin no_plugin;
    const CommandResult r = run_penumbra(folder, "render env.json -q -o out.exr");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("sky.ppm"), std::string::npos) << r.output;
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
