// Every version penumbra reports is the one of `project(penumbra VERSION ...)` in CMakeLists.txt,
// handed to this test by CMake as PENUMBRA_PROJECT_VERSION.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <nlohmann/json.hpp>

#include "api/embedded_documents.h"
#include "api/version.h"
#include "tests/app/app_test_util.h"

namespace penumbra::test {
namespace {

const std::string kProjectVersion = PENUMBRA_PROJECT_VERSION;

std::string software_attribute(const std::string& path) {
  try {
    const Imf::InputFile input(path.c_str());
    const auto* software = input.header().findTypedAttribute<Imf::StringAttribute>("Software");
    return software ? software->value() : "no Software attribute in " + path;
  } catch (const std::exception& e) {
    return "cannot open " + path + ": " + e.what();
  }
}

TEST(Version, GeneratedHeaderIsTheProjects) {
  EXPECT_EQ(api::kVersion, kProjectVersion);
  EXPECT_EQ(api::kSoftwareName, "penumbra " + kProjectVersion);
}

TEST(Version, CommandLine) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "penumbra " + kProjectVersion + "\n");
}

// The document the service serves at /v1/openapi.json.
TEST(Version, OpenApiDocument) {
  const std::string* text = api::embedded_document("openapi.json");
  ASSERT_NE(text, nullptr);
  EXPECT_EQ(nlohmann::json::parse(*text)["info"]["version"], kProjectVersion);
}

TEST(Version, ImageMetadata) {
  SceneFolder folder;
  const CommandResult r = run_penumbra(folder, "render scene.json -q -o out.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(software_attribute(folder.file("out.exr")), "penumbra " + kProjectVersion);
}

}  // namespace
}  // namespace penumbra::test
