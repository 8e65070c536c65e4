// The job envelope and the manifest-name rules (api/job_submission.h).
#include "api/job_submission.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace penumbra::test {
namespace {

const std::string kHash(64, 'a');

TEST(ManifestNames, PlainRelativePathsPass) {
  const api::ManifestLimits l;
  for (const std::string& name : std::vector<std::string>{"bunny.ply", "textures/wood.png", "%2e%2e/x.ply", "a b/c-d_e.f",
                                 ".hidden", "...", std::string(255, 'x')})
    EXPECT_FALSE(api::manifest_name_problem(name, l)) << name;
}

TEST(ManifestNames, NamesThatCouldLeaveTheFolderFail) {
  const api::ManifestLimits l;
  for (const std::string& name : std::vector<std::string>{"", "/etc/passwd", "..", "../x", "a/../../x", "a/..", "./x", "a/./b", "a//b", "a/",
        "a\\b", std::string("a\0b", 3), "a\nb", "a\x7f", std::string(256, 'x'),
        std::string(1025, 'x')})
    EXPECT_TRUE(api::manifest_name_problem(name, l)) << name;
  std::string deep;
  for (int i = 0; i < 16; ++i) deep += (i ? "/" : "") + std::string("d");
  EXPECT_FALSE(api::manifest_name_problem(deep, l)) << "16 components";
  EXPECT_TRUE(api::manifest_name_problem(deep + "/d", l)) << "17 components";
}

TEST(HashReferences, OnlyLowercaseSha256) {
  EXPECT_EQ(api::parse_hash_reference("sha256:" + kHash), kHash);
  EXPECT_FALSE(api::parse_hash_reference(kHash));
  EXPECT_FALSE(api::parse_hash_reference("sha256:" + std::string(64, 'A')));
  EXPECT_FALSE(api::parse_hash_reference("sha256:" + std::string(63, 'a')));
  EXPECT_FALSE(api::parse_hash_reference("sha1:" + kHash));
}

TEST(JobSubmission, BareSceneIsPassedThroughUnchanged) {
  const std::string body = R"({"version": 1, "objects": []})";
  const auto s = api::parse_job_submission(body, 64, {});
  EXPECT_TRUE(s.ok());
  EXPECT_FALSE(s.enveloped);
  EXPECT_EQ(s.scene_text, body);
}

TEST(JobSubmission, EnvelopeSplitsSceneAndSortedManifest) {
  const std::string body = R"({"scene": {"version": 1}, "assets": {"b/x.ply": "sha256:)" + kHash +
                           R"(", "a.png": "sha256:)" + kHash + R"("}})";
  const auto s = api::parse_job_submission(body, 64, {});
  ASSERT_TRUE(s.ok()) << s.errors[0].to_string();
  EXPECT_TRUE(s.enveloped);
  EXPECT_EQ(nlohmann::json::parse(s.scene_text), nlohmann::json::parse(R"({"version": 1})"));
  ASSERT_EQ(s.assets.size(), 2u);
  EXPECT_EQ(s.assets[0].name, "a.png");
  EXPECT_EQ(s.assets[1].name, "b/x.ply");
  EXPECT_EQ(s.assets[1].hash, kHash);
}

TEST(JobSubmission, ErrorsCarryPointers) {
  const auto s = api::parse_job_submission(
      R"({"scene": 3, "assets": {"../x": "sha256:)" + kHash + R"(", "y": "md5:1", "a": "sha256:)" +
          kHash + R"(", "a/b": "sha256:)" + kHash + R"("}, "notify": {}})",
      64, {});
  ASSERT_FALSE(s.ok());
  std::vector<std::string> pointers;
  for (const auto& e : s.errors) pointers.push_back(e.pointer);
  EXPECT_EQ(pointers, (std::vector<std::string>{"/notify", "/scene", "/assets/..~1x", "/assets/y",
                                                "/assets/a~1b"}));
}

TEST(JobSubmission, FileCountAtTheBoundary) {
  api::ManifestLimits l;
  l.max_files = 2;
  const auto body = [&](int n) {
    std::string assets;
    for (int i = 0; i < n; ++i)
      assets += (i ? "," : "") + std::string("\"f") + std::to_string(i) + "\": \"sha256:" + kHash + "\"";
    return R"({"scene": {}, "assets": {)" + assets + "}}";
  };
  EXPECT_TRUE(api::parse_job_submission(body(2), 64, l).ok());
  const auto over = api::parse_job_submission(body(3), 64, l);
  ASSERT_FALSE(over.ok());
  EXPECT_EQ(over.errors[0].pointer, "/assets");
}

TEST(JobSubmission, SyntaxErrorsAreSyntax) {
  EXPECT_EQ(api::parse_job_submission("{", 64, {}).kind, api::LoadErrorKind::kSyntax);
}

}  // namespace
}  // namespace penumbra::test
