// Asset paths stay inside the scene's folder; every refusal names the field.
#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>

#include "api/asset_path.h"
#include "api/diagnostics.h"

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class AssetPath : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = fs::temp_directory_path() / ("penumbra_asset_path_" + std::to_string(::getpid()));
    fs::remove_all(base_);
    fs::create_directories(base_ / "scene" / "meshes");
    fs::create_directories(base_ / "outside");
    std::ofstream(base_ / "scene" / "meshes" / "a.ply") << "ply";
    std::ofstream(base_ / "outside" / "secret.txt") << "secret";
    fs::create_symlink(base_ / "outside" / "secret.txt", base_ / "scene" / "link.txt");
    fs::create_symlink(base_ / "scene" / "meshes" / "a.ply", base_ / "scene" / "inside_link.ply");
    folder_.root = base_ / "scene";
  }
  void TearDown() override { fs::remove_all(base_); }

  // The error message on "/objects/0/file", or "" if the path was accepted.
  std::string refusal(const std::string& relative) {
    api::Diagnostics diag;
    const auto path = api::resolve_asset_path(folder_, relative, "/objects/0/file", diag);
    auto errors = diag.take_errors();
    if (path) {
      EXPECT_TRUE(errors.empty());
      return "";
    }
    EXPECT_EQ(errors.size(), 1u);
    EXPECT_EQ(errors.at(0).pointer, "/objects/0/file");
    return errors.at(0).message;
  }

  fs::path base_;
  api::AssetFolder folder_;
};

TEST_F(AssetPath, RelativePathsInsideTheFolderResolve) {
  EXPECT_EQ(refusal("meshes/a.ply"), "");
  EXPECT_EQ(refusal("./meshes/a.ply"), "");
  EXPECT_EQ(refusal("inside_link.ply"), "");  // a link that stays inside is fine
}

TEST_F(AssetPath, AbsoluteParentAndLinksOutAreRefused) {
  EXPECT_NE(refusal((base_ / "scene" / "meshes" / "a.ply").string()).find("not absolute"), std::string::npos);
  EXPECT_NE(refusal("../outside/secret.txt").find("'..'"), std::string::npos);
  EXPECT_NE(refusal("meshes/../meshes/a.ply").find("'..'"), std::string::npos);
  EXPECT_NE(refusal("link.txt").find("leads outside"), std::string::npos);
}

TEST_F(AssetPath, MissingEmptyDirectoryAndOversizedAreRefused) {
  EXPECT_NE(refusal("meshes/none.ply").find("no such file"), std::string::npos);
  EXPECT_NE(refusal("").find("not empty"), std::string::npos);
  EXPECT_NE(refusal("meshes").find("regular file"), std::string::npos);
  folder_.max_file_bytes = 2;
  EXPECT_NE(refusal("meshes/a.ply").find("larger than"), std::string::npos);
}

TEST_F(AssetPath, NoFolderMeansNoFiles) {
  folder_.root.clear();
  EXPECT_NE(refusal("meshes/a.ply").find("no asset folder"), std::string::npos);
}

}  // namespace
}  // namespace penumbra::test
