// The one-shot job forms over real HTTP (issue 12): a multipart form with the scene and its
// files (curl -F), a glTF binary body with render settings in the query; glTF URIs that try to
// leave the job's folder; a symbolic link planted in the store.
#include <gtest/gtest.h>

#include "asset_support.h"

namespace penumbra::test {
namespace {

httplib::Result post_form(httplib::Client& c, const httplib::MultipartFormDataItems& items,
                          const std::string& path = "/v1/jobs") {
  return c.Post(path.c_str(), items);
}

TEST(OneShotJobs, MultipartFormWithSceneAndMeshRenders) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  auto res = post_form(*c, {{"scene", mesh_file_scene().dump(), "scene.json", "application/json"},
                            {"meshes/trefoil.ply", trefoil_ply(), "trefoil.ply", ""}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const Json job = wait_for_state(*c, Json::parse(res->body)["id"], {"succeeded", "failed"});
  EXPECT_EQ(job["state"], "succeeded") << job.dump();
  // The file went into the store: a later JSON job can name it by hash.
  EXPECT_EQ(c->Head(("/v1/assets/" + sha(trefoil_ply())).c_str())->status, 200);
}

TEST(OneShotJobs, MultipartErrorsNameThePart) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-job-files", "2"});
  auto c = server.client();
  const auto pointer_of = [&](const httplib::MultipartFormDataItems& items, int status = 422) {
    auto res = post_form(*c, items);
    EXPECT_EQ(res->status, status) << res->body;
    const Json body = Json::parse(res->body);
    return body.contains("errors") ? body["errors"][0].value("pointer", "") : std::string();
  };
  const std::string ply = trefoil_ply();
  EXPECT_EQ(pointer_of({{"meshes/trefoil.ply", ply, "t.ply", ""}}), "/scene");
  EXPECT_EQ(pointer_of({{"scene", mesh_file_scene().dump(), "", ""},
                        {"../meshes/trefoil.ply", ply, "t.ply", ""}}),
            "/assets/..~1meshes~1trefoil.ply");
  EXPECT_EQ(pointer_of({{"scene", mesh_file_scene().dump(), "", ""}, {"/etc/passwd", "x", "", ""}}),
            "/assets/~1etc~1passwd");
  // The scene names a file no part carries.
  EXPECT_EQ(pointer_of({{"scene", mesh_file_scene().dump(), "", ""}, {"other.ply", ply, "", ""}}),
            "/scene/objects/2/file");
  // Not JSON.
  EXPECT_EQ(pointer_of({{"scene", "{nope", "", ""}}, 400), "/scene");
  // Three parts are two files and the scene: within --max-job-files 2; four are not.
  EXPECT_EQ(post_form(*c, {{"scene", tiny_scene(4, 4, 1).dump(), "", ""},
                           {"a", "1", "", ""}, {"b", "2", "", ""}})->status, 202);
  EXPECT_EQ(post_form(*c, {{"scene", tiny_scene(4, 4, 1).dump(), "", ""},
                           {"a", "1", "", ""}, {"b", "2", "", ""}, {"c", "3", "", ""}})->status,
            400);
}

TEST(OneShotJobs, MalformedMultipartBodiesAre400) {
  TempDir dir;
  ServerProcess server(dir.path());
  for (const std::string& body :
       {std::string("no boundary here"), std::string("--XYZ\r\nContent-Disposition: form-data\r\n\r\nx\r\n--XYZ--"),
        std::string("--XYZ\r\nContent-Disposition: form-data; name=\"scene\"\r\n\r\n{}"),
        std::string("--XYZ\r\nContent-Disposition: form-data; name=\"scene\r\n\r\n{}\r\n--XYZ--")}) {
    const std::string request =
        "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; boundary=XYZ\r\n"
        "Content-Length: " + std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body;
    const std::string answer = raw_request(server.port(), request);
    EXPECT_EQ(raw_status(answer), 400) << body << "\n" << answer;
    EXPECT_NE(answer.find("malformed-form"), std::string::npos) << answer;
  }
}

TEST(OneShotJobs, GlbBodyRendersWithQuerySettings) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string glb = read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/gltf_showcase.glb");
  auto res = c->Post("/v1/jobs?width=40&height=30&spp=2", glb, "model/gltf-binary");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const Json job = wait_for_state(*c, Json::parse(res->body)["id"], {"succeeded", "failed"});
  EXPECT_EQ(job["state"], "succeeded") << job.dump();
  EXPECT_EQ(job["render"]["width"], 40);
  EXPECT_EQ(job["render"]["height"], 30);
  EXPECT_EQ(job["render"]["spp"], 2);
  auto bad_param = c->Post("/v1/jobs?threads=4", glb, "model/gltf-binary");
  EXPECT_EQ(bad_param->status, 400) << bad_param->body;
  auto bad_value = c->Post("/v1/jobs?width=-3", glb, "model/gltf-binary");
  ASSERT_EQ(bad_value->status, 422) << bad_value->body;
  EXPECT_EQ(Json::parse(bad_value->body)["errors"][0]["pointer"], "/scene/render/width");
  auto not_glb = c->Post("/v1/jobs", std::string("not a glb at all"), "model/gltf-binary");
  ASSERT_EQ(not_glb->status, 422) << not_glb->body;
}

// A .gltf whose buffer URI tries to leave the job's folder, as a relative path, an absolute
// path and a URL-encoded one: each refused, naming the file.
TEST(OneShotJobs, GltfUrisCannotLeaveTheJobFolder) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  for (const char* uri :
       {"../../etc/passwd", "/etc/passwd", "%2e%2e/%2e%2e/etc/passwd", "file:///etc/passwd"}) {
    const Json gltf = {
        {"asset", {{"version", "2.0"}}},
        {"buffers", {{{"uri", uri}, {"byteLength", 36}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
           {"min", {0, 0, 0}}, {"max", {1, 1, 0}}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"scenes", {{{"nodes", {0}}}}},
        {"scene", 0}};
    Json scene = tiny_scene(4, 4, 1);
    scene["objects"].push_back({{"type", "gltf"}, {"file", "model.gltf"}});
    auto res = post_form(*c, {{"scene", scene.dump(), "", ""}, {"model.gltf", gltf.dump(), "", ""}});
    ASSERT_EQ(res->status, 422) << uri << ": " << res->body;
    const Json errors = Json::parse(res->body)["errors"];
    EXPECT_EQ(errors[0]["pointer"].get<std::string>().rfind("/scene/objects/", 0), 0u) << res->body;
  }
}

// Only regular files named by their hash are served from the store: a symbolic link planted in
// it (to /etc/passwd) is removed at start, never served or linked into a job.
TEST(OneShotJobs, SymlinkPlantedInTheStoreIsNeverServed) {
  TempDir dir;
  const std::string passwd = read_file("/etc/passwd");
  const std::string hash = sha(passwd);
  { ServerProcess first(dir.path()); }
  std::filesystem::create_symlink("/etc/passwd", dir.path() + "/assets/sha256/" + hash);
  ServerProcess server(dir.path());
  auto c = server.client();
  EXPECT_EQ(c->Head(("/v1/assets/" + hash).c_str())->status, 404);
  EXPECT_FALSE(std::filesystem::is_symlink(dir.path() + "/assets/sha256/" + hash));
}

}  // namespace
}  // namespace penumbra::test
