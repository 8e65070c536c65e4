// Every error status of the API, each an application/problem+json document (RFC 9457).
#include <gtest/gtest.h>

#include <set>

#include "server_process.h"

namespace penumbra::test {
namespace {

Json expect_problem(const httplib::Result& res, int status, const std::string& type = "") {
  EXPECT_TRUE(res);
  if (!res) return {};
  EXPECT_EQ(res->status, status) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json");
  const Json p = Json::parse(res->body);
  EXPECT_EQ(p["status"], status);
  EXPECT_TRUE(p["title"].is_string());
  if (!type.empty()) {
    EXPECT_EQ(p["type"], "urn:penumbra:problem:" + type);
  }
  return p;
}

class ErrorResponses : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    server_ = new ServerProcess(dir_->path(), {"--max-body", "4096"});
  }
  static void TearDownTestSuite() {
    delete server_;
    delete dir_;
  }
  static TempDir* dir_;
  static ServerProcess* server_;
};
TempDir* ErrorResponses::dir_ = nullptr;
ServerProcess* ErrorResponses::server_ = nullptr;

TEST_F(ErrorResponses, MalformedJsonIs400) {
  auto c = server_->client();
  const Json p = expect_problem(post_json(*c, "/v1/jobs", "{\"version\": 1,"), 400, "malformed-json");
  EXPECT_FALSE(p["detail"].get<std::string>().empty());
  expect_problem(post_json(*c, "/v1/jobs", ""), 400, "malformed-json");
  expect_problem(post_json(*c, "/v1/jobs", "[1e400]"), 400);
  // Nesting deeper than the cap is refused before anything recurses over it.
  expect_problem(post_json(*c, "/v1/jobs", std::string(100, '[') + std::string(100, ']')), 400);
}

TEST_F(ErrorResponses, InvalidSceneIs422WithEveryPointerAndTheValidateMessages) {
  auto c = server_->client();
  const std::string bad =
      R"({"version":1,"render":{"width":-3,"spp":0},"camera":{"position":[0,0,0],"look_at":[0,0,-1]},)"
      R"("objects":[{"type":"sphere","center":[0,0,-3],"radius":-1,"material":"nope"}]})";
  const Json p = expect_problem(post_json(*c, "/v1/jobs", bad), 422, "invalid-scene");
  std::set<std::string> pointers;
  for (const auto& e : p["errors"]) pointers.insert(e["pointer"]);
  EXPECT_EQ(pointers, (std::set<std::string>{"/render/width", "/render/spp", "/objects/0/radius",
                                             "/objects/0/material"}));
  // The same messages as `penumbra validate`.
  const std::string path = dir_->path() + "/bad.json";
  std::ofstream(path) << bad;
  const std::string cmd = std::string(PENUMBRA_BINARY) + " validate " + path + " 2>&1";
  std::string validate_output;
  FILE* f = ::popen(cmd.c_str(), "r");
  char buf[512];
  while (std::fgets(buf, sizeof buf, f)) validate_output += buf;
  ::pclose(f);
  for (const auto& e : p["errors"]) {
    const std::string line = e["pointer"].get<std::string>() + ": " + e["detail"].get<std::string>();
    EXPECT_NE(validate_output.find(line), std::string::npos) << line << "\n" << validate_output;
  }
}

TEST_F(ErrorResponses, ScenesCannotNameFilesOnTheServer) {
  auto c = server_->client();
  Json scene = tiny_scene();
  scene["include"] = "/etc/passwd";
  Json p = expect_problem(post_json(*c, "/v1/jobs", scene.dump()), 422, "invalid-scene");
  EXPECT_EQ(p["errors"][0]["pointer"], "/include");
  Json mesh_from_file = tiny_scene();
  mesh_from_file["objects"].push_back({{"type", "mesh"}, {"file", "/etc/passwd"}, {"material", "white"}});
  p = expect_problem(post_json(*c, "/v1/jobs", mesh_from_file.dump()), 422, "invalid-scene");
  bool names_file = false;
  for (const auto& e : p["errors"]) names_file |= e["pointer"].get<std::string>().find("/file") != std::string::npos;
  EXPECT_TRUE(names_file) << p.dump();
  EXPECT_EQ(p.dump().find("root:"), std::string::npos) << "nothing of the file comes back";
}

TEST_F(ErrorResponses, UnknownJobAndRouteAre404WrongMethodIs405) {
  auto c = server_->client();
  expect_problem(c->Get("/v1/jobs/0123456789abcdef01234567"), 404);
  expect_problem(c->Get("/v1/jobs/0123456789abcdef01234567/result"), 404);
  expect_problem(c->Delete("/v1/jobs/0123456789abcdef01234567"), 404);
  expect_problem(c->Get("/v1/jobs/not-an-id"), 404);
  expect_problem(c->Get("/v1/jobs/..%2f..%2fjobs.db"), 404);
  expect_problem(c->Get("/nowhere"), 404);
  auto put = c->Put("/v1/jobs", "{}", "application/json");
  expect_problem(put, 405);
  EXPECT_EQ(put->get_header_value("Allow"), "GET, HEAD, POST");
  expect_problem(c->Get("/v1/render"), 405);
}

TEST_F(ErrorResponses, ResultOfAQueuedOrRunningJobIs409WithRetryAfter) {
  auto c = server_->client();
  const std::string id = submit(*c, long_scene());
  auto res = c->Get(("/v1/jobs/" + id + "/result").c_str());
  const Json p = expect_problem(res, 409, "result-not-ready");
  EXPECT_FALSE(res->get_header_value("Retry-After").empty());
  EXPECT_TRUE(p["state"] == "queued" || p["state"] == "running");
  auto job = c->Get(("/v1/jobs/" + id).c_str());
  EXPECT_FALSE(job->get_header_value("Retry-After").empty()) << "unfinished jobs say when to poll";
  EXPECT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status, 200);
  const Json cancelled = expect_problem(c->Get(("/v1/jobs/" + id + "/result").c_str()), 409);
  EXPECT_EQ(cancelled["state"], "cancelled");
}

TEST_F(ErrorResponses, BodyLimitAtTheBoundary) {
  auto c = server_->client();
  std::string body = tiny_scene(8, 8, 1).dump();
  ASSERT_LT(body.size(), 4096u);
  body.append(4096 - body.size(), ' ');  // JSON allows trailing whitespace
  auto ok = post_json(*c, "/v1/jobs", body);
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 202) << "a body of exactly --max-body bytes is accepted";
  body.push_back(' ');
  const Json p = expect_problem(post_json(*c, "/v1/jobs", body), 413, "body-too-large");
  EXPECT_EQ(p["limit"], 4096);
  expect_problem(c->Post("/v1/render", body, "application/json"), 413);
}

TEST_F(ErrorResponses, UnsupportedMediaTypesAre415) {
  auto c = server_->client();
  const std::string body = tiny_scene(8, 8, 1).dump();
  expect_problem(c->Post("/v1/jobs", body, "text/plain"), 415, "unsupported-media-type");
  // A multipart form is the one-shot job form (issue 12), parsed by our own bounded parser: a
  // JSON body under that type is a malformed form, never parsed by the library.
  expect_problem(c->Post("/v1/jobs", body, "multipart/form-data; boundary=x"), 400,
                 "malformed-form");
  expect_problem(c->Post("/v1/render", body, "multipart/form-data; boundary=x"), 415);
  EXPECT_EQ(c->Post("/v1/jobs", body, "application/json; charset=utf-8")->status, 202);
  expect_problem(c->Post("/v1/jobs", {{"Content-Encoding", "gzip"}}, body, "application/json"), 415,
                 "unsupported-content-encoding");
}

TEST_F(ErrorResponses, ChunkedAndLengthlessBodiesAreRefused) {
  const std::string chunked = raw_request(server_->port(),
                                          "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                                          "Transfer-Encoding: chunked\r\n\r\n5\r\nhello\r\n0\r\n\r\n");
  EXPECT_EQ(raw_status(chunked), 411) << chunked;
  EXPECT_NE(chunked.find("application/problem+json"), std::string::npos);
  const std::string no_length =
      raw_request(server_->port(), "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(no_length), 411) << no_length;
  const std::string huge_claim = raw_request(
      server_->port(), "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Length: 99999999999\r\n\r\n{");
  EXPECT_EQ(raw_status(huge_claim), 413) << "refused from the header, before reading any body";
}

TEST_F(ErrorResponses, MultiRangeIs416AndUnacceptableIs406) {
  auto c = server_->client();
  const std::string id = submit(*c, tiny_scene(8, 8, 1));
  wait_for_state(*c, id, {"succeeded"});
  const std::string result = "/v1/jobs/" + id + "/result";
  expect_problem(c->Get(result.c_str(), {{"Range", "bytes=0-1,4-5"}}), 416, "multiple-ranges");
  auto one = c->Get(result.c_str(), {{"Range", "bytes=0-7"}});
  EXPECT_EQ(one->status, 206);
  EXPECT_EQ(one->body.size(), 8u);
  expect_problem(c->Get(result.c_str(), {{"Accept", "application/json"}}), 406, "not-acceptable");
  expect_problem(c->Get((result + "?format=jpeg").c_str()), 400, "invalid-parameter");
}

TEST_F(ErrorResponses, InvalidIdempotencyKeyIs400) {
  auto c = server_->client();
  expect_problem(post_json(*c, "/v1/jobs", tiny_scene().dump(), {{"Idempotency-Key", std::string(300, 'k')}}),
                 400, "invalid-idempotency-key");
}

}  // namespace
}  // namespace penumbra::test
