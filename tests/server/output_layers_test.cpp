// Output layers through the real binary over HTTP: a job whose scene asks for render.outputs
// serves each layer alone (?layer=, PNG or EXR), the multi-layer EXR with plain names and in
// Blender's layout (?layout=blender); unknown or unrendered layers are typed problems.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>

#include "server_process.h"

namespace penumbra::test {
namespace {

bool is_png(const std::string& b) { return b.size() > 8 && b.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0; }
bool is_exr(const std::string& b) { return b.size() > 4 && b.compare(0, 4, "\x76\x2f\x31\x01") == 0; }
// An EXR's header lists its channel names as NUL-terminated strings, uncompressed: the name
// followed by NUL and not preceded by a name character ("R" must not match "albedo.R").
bool has_channel(const std::string& exr, const std::string& name) {
  const std::string needle = name + std::string("\0", 1);
  for (size_t at = exr.find(needle); at != std::string::npos; at = exr.find(needle, at + 1)) {
    const char before = at > 0 ? exr[at - 1] : '\0';
    if (!std::isalnum(static_cast<unsigned char>(before)) && before != '.' && before != ' ') return true;
  }
  return false;
}

std::string problem_type(const httplib::Result& res) {
  return Json::parse(res->body).value("type", std::string());
}

TEST(OutputLayersHttp, LayersLayoutsAndProblems) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  Json scene = tiny_scene(20, 12, 2);
  scene["render"]["outputs"] = {"albedo", "normal", "depth"};
  const std::string id = submit(*c, scene);
  Json plain_scene = tiny_scene(20, 12, 2);
  const std::string plain_id = submit(*c, plain_scene);
  ASSERT_EQ(wait_for_state(*c, id, {"succeeded", "failed"})["state"], "succeeded");
  ASSERT_EQ(wait_for_state(*c, plain_id, {"succeeded", "failed"})["state"], "succeeded");
  const std::string base = "/v1/jobs/" + id + "/result";

  auto exr = c->Get((base + "?format=exr").c_str());
  ASSERT_EQ(exr->status, 200);
  ASSERT_TRUE(is_exr(exr->body));
  for (const char* ch : {"R", "G", "B", "albedo.R", "albedo.B", "normal.X", "normal.Z", "depth.Z"})
    EXPECT_TRUE(has_channel(exr->body, ch)) << ch;
  EXPECT_FALSE(has_channel(exr->body, "ViewLayer.Combined.R"));

  auto blender = c->Get((base + "?layout=blender").c_str());
  ASSERT_EQ(blender->status, 200) << blender->body;
  EXPECT_EQ(blender->get_header_value("Content-Type"), "image/x-exr");
  for (const char* ch : {"ViewLayer.Combined.R", "ViewLayer.Combined.A", "ViewLayer.Denoising Albedo.G",
                         "ViewLayer.Normal.Y", "ViewLayer.Depth.Z"})
    EXPECT_TRUE(has_channel(blender->body, ch)) << ch;
  EXPECT_NE(blender->get_header_value("ETag"), exr->get_header_value("ETag"));

  for (const char* layer : {"albedo", "normal", "depth"}) {
    auto png = c->Get((base + "?layer=" + layer).c_str());
    ASSERT_EQ(png->status, 200) << layer;
    EXPECT_TRUE(is_png(png->body)) << layer;
    EXPECT_NE(png->get_header_value("Content-Disposition").find(std::string(".") + layer + ".png"),
              std::string::npos);
    auto one = c->Get((base + "?layer=" + layer + "&format=exr").c_str());
    ASSERT_EQ(one->status, 200) << layer;
    EXPECT_TRUE(is_exr(one->body));
  }
  auto depth = c->Get((base + "?layer=depth&format=exr").c_str());
  EXPECT_TRUE(has_channel(depth->body, "Z"));
  auto beauty = c->Get((base + "?layer=beauty").c_str());
  EXPECT_EQ(beauty->status, 200);
  EXPECT_EQ(beauty->body, c->Get(base.c_str())->body);

  // A name that is no layer: 422; a layer the job did not ask for: 404.
  auto unknown = c->Get((base + "?layer=specular").c_str());
  EXPECT_EQ(unknown->status, 422);
  EXPECT_EQ(problem_type(unknown), "urn:penumbra:problem:unknown-layer");
  EXPECT_EQ(Json::parse(unknown->body)["errors"][0]["parameter"], "layer");
  auto missing = c->Get(("/v1/jobs/" + plain_id + "/result?layer=normal").c_str());
  EXPECT_EQ(missing->status, 404);
  EXPECT_EQ(problem_type(missing), "urn:penumbra:problem:layer-not-rendered");
  // A job without layers stores no Blender copy: 404 of the same type.
  auto plain_blender = c->Get(("/v1/jobs/" + plain_id + "/result?layout=blender").c_str());
  EXPECT_EQ(plain_blender->status, 404);
  EXPECT_EQ(problem_type(plain_blender), "urn:penumbra:problem:layer-not-rendered");
  std::size_t plain_files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path() + "/results"))
    if (e.path().filename().string().rfind(plain_id, 0) == 0) ++plain_files;
  EXPECT_EQ(plain_files, 2u) << "a job without layers stores its PNG and EXR only";
  auto bad_layout = c->Get((base + "?layout=nuke").c_str());
  EXPECT_EQ(bad_layout->status, 422);
  EXPECT_EQ(problem_type(bad_layout), "urn:penumbra:problem:unknown-layout");
  auto conflict = c->Get((base + "?layout=blender&format=png").c_str());
  EXPECT_EQ(conflict->status, 422);
  EXPECT_EQ(problem_type(conflict), "urn:penumbra:problem:layout-conflict");
  auto conflict2 = c->Get((base + "?layout=blender&layer=depth").c_str());
  EXPECT_EQ(conflict2->status, 422);

  // Deleting the job removes every file of its result.
  ASSERT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status, 204);
  std::size_t left = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path() + "/results"))
    if (e.path().filename().string().rfind(id, 0) == 0) ++left;
  EXPECT_EQ(left, 0u);
}

TEST(OutputLayersHttp, SubmissionWithBadOutputsIs422WithPointer) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  Json scene = tiny_scene(8, 8, 1);
  scene["render"]["outputs"] = {"albedo", "z"};
  auto res = post_json(*c, "/v1/jobs", scene.dump());
  ASSERT_EQ(res->status, 422) << res->body;
  EXPECT_NE(res->body.find("/render/outputs/1"), std::string::npos) << res->body;
}

}  // namespace
}  // namespace penumbra::test
