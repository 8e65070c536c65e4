// The asset store and job manifests over real HTTP against `penumbra serve` (issue 12): upload,
// verification, idempotence (also with Expect: 100-continue), de-duplication, manifest errors,
// path traversal, durability across kill -9, limits at their boundary and eviction.
#include <gtest/gtest.h>

#include <csignal>

#include "asset_support.h"

namespace penumbra::test {
namespace {

TEST(Assets, UploadedPlyRendersThroughAManifest) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string ply = trefoil_ply();
  const std::string hash = sha(ply);
  EXPECT_EQ(c->Head(("/v1/assets/" + hash).c_str())->status, 404);
  auto put = put_asset(*c, ply);
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 201) << put->body;
  EXPECT_EQ(Json::parse(put->body)["hash"], "sha256:" + hash);
  EXPECT_EQ(Json::parse(put->body)["size"], ply.size());
  auto head = c->Head(("/v1/assets/" + hash).c_str());
  EXPECT_EQ(head->status, 200);
  EXPECT_EQ(head->get_header_value("Content-Length"), std::to_string(ply.size()));
  EXPECT_EQ(c->Get(("/v1/assets/" + hash).c_str())->body, ply);
  EXPECT_EQ(put_asset(*c, ply)->status, 200) << "a known hash is answered 200, not stored again";

  const AssetSubmission s = submit_with_assets(*c, mesh_file_scene(), {{"meshes/trefoil.ply", ply}});
    ASSERT_EQ(s.status, 202) << s.body;
  EXPECT_EQ(s.uploads, 0);
  const std::string id = Json::parse(s.body)["id"];
  const Json job = wait_for_state(*c, id, {"succeeded", "failed"});
  EXPECT_EQ(job["state"], "succeeded") << job.dump();
  // The render saw the mesh: the image is not the mesh-less scene's.
  Json without_mesh = mesh_file_scene();
  without_mesh["objects"].erase(2);
  const std::string plain = submit(*c, without_mesh);
  wait_for_state(*c, plain, {"succeeded"});
  EXPECT_NE(c->Get(("/v1/jobs/" + id + "/result?format=exr").c_str())->body,
            c->Get(("/v1/jobs/" + plain + "/result?format=exr").c_str())->body);
}

TEST(Assets, SecondSubmissionOfTheSameSceneUploadsNothing) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::map<std::string, std::string> files = {{"meshes/trefoil.ply", trefoil_ply()}};
  const AssetSubmission first = submit_with_assets(*c, mesh_file_scene(), files);
  ASSERT_EQ(first.status, 202) << first.body << " uploads " << first.uploads;
  EXPECT_EQ(first.bytes_uploaded, trefoil_ply().size());
  const AssetSubmission second = submit_with_assets(*c, mesh_file_scene(), files);
  ASSERT_EQ(second.status, 202) << second.body;
  EXPECT_EQ(second.bytes_uploaded, 0u);
  EXPECT_EQ(second.uploads, 0);
}

TEST(Assets, MismatchedBodyIs422AndNeverVisible) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string claimed = sha("the real content");
  auto put = put_asset(*c, "other content", claimed);
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 422) << put->body;
  EXPECT_EQ(Json::parse(put->body)["actual"], "sha256:" + sha("other content"));
  EXPECT_EQ(c->Head(("/v1/assets/" + claimed).c_str())->status, 404);
  EXPECT_EQ(c->Head(("/v1/assets/" + sha("other content")).c_str())->status, 404);
  EXPECT_EQ(put_asset(*c, "x", "ABC")->status, 400);
  EXPECT_EQ(put_asset(*c, "x", std::string(64, 'A'))->status, 400) << "hex must be lowercase";
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() + "/assets/tmp"));
}

TEST(Assets, MissingListsOnlyUnknownHashes) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  ASSERT_EQ(put_asset(*c, "known")->status, 201);
  auto res = post_json(*c, "/v1/assets/missing",
                       Json{{"hashes", {"sha256:" + sha("known"), "sha256:" + sha("unknown")}}}.dump());
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(Json::parse(res->body)["missing"], Json::array({"sha256:" + sha("unknown")}));
  auto bad = post_json(*c, "/v1/assets/missing", R"({"hashes": ["sha256:abc", 3]})");
  ASSERT_EQ(bad->status, 422);
  const Json errors = Json::parse(bad->body)["errors"];
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0]["pointer"], "/hashes/0");
  EXPECT_EQ(errors[1]["pointer"], "/hashes/1");
}

// A client sending Expect: 100-continue for a hash the server holds gets the final answer at
// once and never sends the body; for a new hash it is told to go on.
TEST(Assets, ExpectContinueSkipsTheBodyOfAKnownAsset) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  ASSERT_EQ(put_asset(*c, "known bytes")->status, 201);
  const auto head = [](const std::string& hash, std::size_t length) {
    return "PUT /v1/assets/" + hash + " HTTP/1.1\r\nHost: x\r\nContent-Length: " +
           std::to_string(length) + "\r\nExpect: 100-continue\r\n\r\n";
  };
  const std::string known = raw_request(server.port(), head(sha("known bytes"), 11));
  EXPECT_EQ(raw_status(known), 200) << known;
  const auto body_at = known.find("\r\n\r\n");
  ASSERT_NE(body_at, std::string::npos) << known;
  EXPECT_EQ(Json::parse(known.substr(body_at + 4))["size"], 11) << known;
  EXPECT_NE(known.find("Connection: close"), std::string::npos) << known;
  const std::string fresh = raw_request(server.port(), head(sha("new bytes"), 9));
  EXPECT_EQ(raw_status(fresh), 100) << fresh;
  // Over the limit: refused before the body is sent.
  const std::string huge = raw_request(server.port(), head(sha("x"), std::size_t(1) << 40));
  EXPECT_EQ(raw_status(huge), 413) << huge;
}

TEST(Assets, ExpectContinueStillNeedsTheToken) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--token", "s3cret"});
  auto c = server.client("s3cret");
  ASSERT_EQ(put_asset(*c, "known bytes")->status, 201);
  const std::string answer = raw_request(
      server.port(), "PUT /v1/assets/" + sha("known bytes") +
                         " HTTP/1.1\r\nHost: x\r\nContent-Length: 11\r\nExpect: 100-continue\r\n\r\n");
  EXPECT_EQ(raw_status(answer), 401) << answer;
}

TEST(Assets, ManifestErrorsNameTheField) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string ply = trefoil_ply();
  const Json scene = mesh_file_scene();
  const auto errors_of = [&](const Json& body) {
    auto res = post_json(*c, "/v1/jobs", body.dump());
    EXPECT_EQ(res->status, 422) << body.dump().substr(0, 300) << "\n" << res->body;
    return Json::parse(res->body)["errors"];
  };
  // The hash is not stored.
  Json e = errors_of({{"scene", scene}, {"assets", {{"meshes/trefoil.ply", "sha256:" + sha(ply)}}}});
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0]["pointer"], "/assets/meshes~1trefoil.ply");
  ASSERT_EQ(put_asset(*c, ply)->status, 201);
  // The scene names a file the manifest does not.
  e = errors_of({{"scene", scene}, {"assets", {{"other.ply", "sha256:" + sha(ply)}}}});
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0]["pointer"], "/scene/objects/2/file");
  EXPECT_NE(e[0]["detail"].get<std::string>().find("manifest"), std::string::npos);
  // A bare scene cannot name files.
  auto bare = post_json(*c, "/v1/jobs", scene.dump());
  ASSERT_EQ(bare->status, 422);
  EXPECT_EQ(Json::parse(bare->body)["errors"][0]["pointer"], "/objects/2/file");
  // Not a hash reference; unknown member.
  e = errors_of({{"scene", scene}, {"assets", {{"meshes/trefoil.ply", sha(ply)}}}, {"extra", 1}});
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0]["pointer"], "/extra");
  EXPECT_EQ(e[1]["pointer"], "/assets/meshes~1trefoil.ply");
}

// Names that would leave the job's folder are refused in the manifest; paths in the scene that
// would are refused by the loader; a URL-encoded name is only a literal, odd file name.
TEST(Assets, PathTraversalThroughManifestNamesIsRefused) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string ply = trefoil_ply();
  ASSERT_EQ(put_asset(*c, ply)->status, 201);
  const std::string ref = "sha256:" + sha(ply);
  for (const std::string& name : std::vector<std::string>{"../../etc/passwd", "/etc/passwd", "meshes/../../x.ply", "a\\b.ply", "./a.ply", "a//b.ply",
        "a/", std::string("a\0b", 3), std::string(300, 'x'), "a/a/a/a/a/a/a/a/a/a/a/a/a/a/a/a/a"}) {
    Json scene = mesh_file_scene();
    scene["objects"][2]["file"] = name;
    auto res = post_json(*c, "/v1/jobs", Json{{"scene", scene}, {"assets", {{name, ref}}}}.dump());
    ASSERT_EQ(res->status, 422) << name << ": " << res->body;
    const Json errors = Json::parse(res->body)["errors"];
    EXPECT_EQ(errors[0]["pointer"].get<std::string>().rfind("/assets/", 0), 0u) << res->body;
  }
  // The scene itself cannot reach out either, whatever the manifest holds.
  for (const std::string path : std::vector<std::string>{"../../etc/passwd", "/etc/passwd", "meshes/../../../etc/passwd"}) {
    Json scene = mesh_file_scene();
    scene["objects"][2]["file"] = path;
    auto res = post_json(*c, "/v1/jobs",
                         Json{{"scene", scene}, {"assets", {{"meshes/trefoil.ply", ref}}}}.dump());
    ASSERT_EQ(res->status, 422) << path;
    EXPECT_EQ(Json::parse(res->body)["errors"][0]["pointer"], "/scene/objects/2/file");
  }
  // "%2e%2e/x.ply" is not decoded: a folder named "%2e%2e", inside the job's folder.
  Json scene = mesh_file_scene();
  scene["objects"][2]["file"] = "%2e%2e/x.ply";
  auto res = post_json(*c, "/v1/jobs", Json{{"scene", scene}, {"assets", {{"%2e%2e/x.ply", ref}}}}.dump());
  ASSERT_EQ(res->status, 202) << res->body;
  const Json job = wait_for_state(*c, Json::parse(res->body)["id"], {"succeeded", "failed"});
  EXPECT_EQ(job["state"], "succeeded") << job.dump();
}

TEST(Assets, AnAcknowledgedUploadSurvivesKillDashNine) {
  TempDir dir;
  const std::string bytes(300000, 'q');
  {
    ServerProcess server(dir.path());
    auto c = server.client();
    ASSERT_EQ(put_asset(*c, bytes)->status, 201);
    server.signal(SIGKILL);
    EXPECT_EQ(server.wait_exit(std::chrono::seconds(5)), 128 + SIGKILL);
  }
  // An upload cut off mid-way leaves only a temporary file, removed at start.
  std::ofstream(dir.path() + "/assets/tmp/cut.part") << "half";
  ServerProcess server(dir.path());
  auto c = server.client();
  auto head = c->Head(("/v1/assets/" + sha(bytes)).c_str());
  EXPECT_EQ(head->status, 200);
  EXPECT_EQ(c->Get(("/v1/assets/" + sha(bytes)).c_str())->body, bytes);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() + "/assets/tmp"));
}

}  // namespace
}  // namespace penumbra::test

namespace penumbra::test {
namespace {

Json enveloped(const Json& scene, const std::map<std::string, std::string>& files) {
  Json manifest = Json::object();
  for (const auto& [name, bytes] : files) manifest[name] = "sha256:" + sha(bytes);
  return {{"scene", scene}, {"assets", manifest}};
}

TEST(AssetLimits, OneAssetsSizeAtTheBoundary) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-asset-size", "1000"});
  auto c = server.client();
  EXPECT_EQ(put_asset(*c, std::string(1000, 'a'))->status, 201);
  auto over = put_asset(*c, std::string(1001, 'b'));
  EXPECT_EQ(over->status, 413) << over->body;
  EXPECT_EQ(Json::parse(over->body)["limit"], 1000);
  // A body longer than --max-body but within --max-asset-size is an upload, not refused.
  ServerProcess wide(dir.path() + "-wide", {"--max-body", "1k", "--max-asset-size", "64k"});
  auto w = wide.client();
  EXPECT_EQ(put_asset(*w, std::string(60000, 'c'))->status, 201);
  EXPECT_EQ(post_json(*w, "/v1/jobs", std::string(2000, ' '))->status, 413);
  std::filesystem::remove_all(dir.path() + "-wide");
}

TEST(AssetLimits, FilesAndBytesPerJobAtTheBoundary) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-job-files", "2", "--max-job-assets", "2000"});
  auto c = server.client();
  const std::string a(1000, 'a'), b(1000, 'b'), d(1, 'd');
  for (const auto* bytes : {&a, &b, &d}) ASSERT_EQ(put_asset(*c, *bytes)->status, 201);
  const Json scene = tiny_scene(4, 4, 1);
  EXPECT_EQ(post_json(*c, "/v1/jobs", enveloped(scene, {{"a", a}, {"b", b}}).dump())->status, 202);
  auto files = post_json(*c, "/v1/jobs", enveloped(scene, {{"a", a}, {"b", b}, {"d", d}}).dump());
  ASSERT_EQ(files->status, 422);
  EXPECT_EQ(Json::parse(files->body)["errors"][0]["pointer"], "/assets");
  const std::string b2 = b + "x";  // 1001 bytes: 2001 in all
  ASSERT_EQ(put_asset(*c, b2)->status, 201);
  auto bytes = post_json(*c, "/v1/jobs", enveloped(scene, {{"a", a}, {"b", b2}}).dump());
  ASSERT_EQ(bytes->status, 422) << bytes->body;
  EXPECT_NE(Json::parse(bytes->body)["errors"][0]["detail"].get<std::string>().find("--max-job-assets"),
            std::string::npos);
}

// The texture's width x height is read from its header: 8 x 8 = 64 pixels.
TEST(AssetLimits, ImagePixelsAtTheBoundary) {
  const std::string png =
      read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/textures/checker.png");
  Json scene = tiny_scene(4, 4, 1);
  scene["materials"]["white"]["color"] = {{"texture", "checker.png"}};
  for (const int limit : {64, 63}) {
    TempDir dir;
    ServerProcess server(dir.path(), {"--max-image-pixels", std::to_string(limit)});
    auto c = server.client();
    ASSERT_EQ(put_asset(*c, png)->status, 201);
    auto res = post_json(*c, "/v1/jobs", enveloped(scene, {{"checker.png", png}}).dump());
    if (limit == 64) {
      EXPECT_EQ(res->status, 202) << res->body;
    } else {
      ASSERT_EQ(res->status, 422) << res->body;
      EXPECT_EQ(Json::parse(res->body)["errors"][0]["pointer"], "/scene/materials/white/color/texture");
    }
  }
}

// Under a small quota the least recently used assets go first, never one a queued or running job
// has in its folder; once that job is gone its files can go too.
TEST(AssetStore, EvictsOldestUnreferencedAssetsFirst) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-asset-store", "300000"});
  auto c = server.client();
  const std::string a(130000, 'a'), b(100000, 'b'), cc(100000, 'c'), d(150000, 'd'), e(200000, 'e');
  const auto present = [&](const std::string& bytes) {
    return c->Head(("/v1/assets/" + sha(bytes)).c_str())->status == 200;
  };
  ASSERT_EQ(put_asset(*c, a)->status, 201);
  auto job = post_json(*c, "/v1/jobs", enveloped(long_scene(), {{"a.bin", a}}).dump());
  ASSERT_EQ(job->status, 202) << job->body;
  const std::string id = Json::parse(job->body)["id"];
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(put_asset(*c, b)->status, 201);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(put_asset(*c, cc)->status, 201);  // 330000: b goes (a is the oldest, but in use)
  EXPECT_TRUE(present(a));
  EXPECT_FALSE(present(b));
  EXPECT_TRUE(present(cc));
  ASSERT_EQ(put_asset(*c, d)->status, 201);  // c goes
  EXPECT_TRUE(present(a));
  EXPECT_FALSE(present(cc));
  EXPECT_TRUE(present(d));
  auto full = put_asset(*c, e);  // no room beside a even without d: refused, nothing evicted
  EXPECT_EQ(full->status, 507) << full->body;
  EXPECT_TRUE(present(a));
  EXPECT_TRUE(present(d));
  EXPECT_FALSE(present(e));
  ASSERT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status / 100, 2);
  wait_for_state(*c, id, {"cancelled"});
  auto after = put_asset(*c, e);  // the job is over: a (the oldest) and d go now
  EXPECT_EQ(after->status, 201) << after->body;
  EXPECT_FALSE(present(a));
  EXPECT_FALSE(present(d));
  EXPECT_TRUE(present(e));
}

}  // namespace
}  // namespace penumbra::test
