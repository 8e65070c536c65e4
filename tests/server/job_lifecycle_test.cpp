// The whole life of a job through the real binary: submit, poll, fetch PNG and EXR, list, delete.
#include <gtest/gtest.h>

#include "server_process.h"

namespace penumbra::test {
namespace {

bool is_png(const std::string& b) { return b.size() > 8 && b.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0; }
bool is_exr(const std::string& b) { return b.size() > 4 && b.compare(0, 4, "\x76\x2f\x31\x01") == 0; }

TEST(JobLifecycle, SubmitPollFetchPngAndExrThenDelete) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();

  auto res = post_json(*c, "/v1/jobs", tiny_scene(24, 16, 2).dump());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const Json accepted = Json::parse(res->body);
  const std::string id = accepted["id"];
  EXPECT_EQ(res->get_header_value("Location"), "/v1/jobs/" + id);
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/json");
  EXPECT_TRUE(accepted["state"] == "queued" || accepted["state"] == "running");
  EXPECT_EQ(accepted["links"]["self"], "/v1/jobs/" + id);
  EXPECT_EQ(accepted["samples_total"], 24 * 16 * 2);

  const Json done = wait_for_state(*c, id, {"succeeded", "failed"});
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["progress"], 1.0);
  EXPECT_EQ(done["samples_done"], 24 * 16 * 2);
  EXPECT_EQ(done["attempts"], 1);
  EXPECT_TRUE(done["created_at"].is_string());
  EXPECT_TRUE(done["started_at"].is_string());
  EXPECT_TRUE(done["finished_at"].is_string());
  EXPECT_GT(done["stats"]["seconds"].get<double>(), 0.0);
  EXPECT_GT(done["stats"]["mrays_per_second"].get<double>(), 0.0);
  EXPECT_EQ(done["render"]["width"], 24);

  auto job = c->Get(("/v1/jobs/" + id).c_str());
  EXPECT_FALSE(job->has_header("Retry-After")) << "finished jobs need no polling";

  auto png = c->Get(("/v1/jobs/" + id + "/result").c_str());
  ASSERT_EQ(png->status, 200);
  EXPECT_EQ(png->get_header_value("Content-Type"), "image/png");
  EXPECT_TRUE(is_png(png->body));

  auto exr = c->Get(("/v1/jobs/" + id + "/result?format=exr").c_str());
  ASSERT_EQ(exr->status, 200);
  EXPECT_EQ(exr->get_header_value("Content-Type"), "image/x-exr");
  EXPECT_TRUE(is_exr(exr->body));

  auto by_accept = c->Get(("/v1/jobs/" + id + "/result").c_str(), {{"Accept", "image/x-exr"}});
  EXPECT_TRUE(is_exr(by_accept->body));
  auto png_by_accept =
      c->Get(("/v1/jobs/" + id + "/result").c_str(), {{"Accept", "text/html, image/png;q=0.9"}});
  EXPECT_TRUE(is_png(png_by_accept->body));
  auto finished_preview = c->Get(("/v1/jobs/" + id + "/result?preview=true").c_str());
  EXPECT_EQ(finished_preview->status, 200) << "a finished job's preview is its result";

  auto list = c->Get("/v1/jobs");
  ASSERT_EQ(list->status, 200);
  const Json jobs = Json::parse(list->body);
  ASSERT_EQ(jobs["jobs"].size(), 1u);
  EXPECT_EQ(jobs["jobs"][0]["id"], id);

  auto del = c->Delete(("/v1/jobs/" + id).c_str());
  EXPECT_EQ(del->status, 204);
  EXPECT_EQ(c->Get(("/v1/jobs/" + id).c_str())->status, 404);
  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result").c_str())->status, 404);
  EXPECT_EQ(c->Delete(("/v1/jobs/" + id).c_str())->status, 204) << "DELETE is idempotent";
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/results/" + id + ".png"));
}

// With render.noise_threshold the render takes fewer samples than width x height x spp: the
// finished job reports what it took, not the cap (and a running one the renderer's estimate).
TEST(JobLifecycle, AdaptiveJobReportsTheSamplesItTook) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  Json scene = tiny_scene(32, 32, 1024);
  scene["render"]["noise_threshold"] = 0.2;
  const std::string id = submit(*c, scene);
  const Json done = wait_for_state(*c, id, {"succeeded", "failed"});
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["progress"], 1.0);
  const uint64_t taken = done["samples_done"];
  EXPECT_EQ(done["samples_total"], taken);
  EXPECT_EQ(done["stats"]["camera_samples"], taken);
  EXPECT_GE(taken, 32u * 32u * 16u);  // every pixel takes the first 16
  EXPECT_LT(taken, 32u * 32u * 1024u / 2);
}

TEST(JobLifecycle, SynchronousRenderAnswersTheImage) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  // Like `curl --data-binary @scene.json`: form content type, taken as JSON.
  auto res = c->Post("/v1/render", tiny_scene(16, 16, 1).dump(), "application/x-www-form-urlencoded");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "image/png");
  EXPECT_TRUE(is_png(res->body));
  const std::string location = res->get_header_value("Content-Location");
  ASSERT_FALSE(location.empty());
  EXPECT_EQ(c->Get(location.c_str())->status, 200) << "the synchronous render is a job too";

  auto exr = c->Post("/v1/render?format=exr", tiny_scene(16, 16, 1).dump(), "application/json");
  ASSERT_EQ(exr->status, 200);
  EXPECT_TRUE(is_exr(exr->body));
}

TEST(JobLifecycle, ListIsNewestFirstPagedAndFiltered) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(submit(*c, tiny_scene(8, 8, 1)));
  for (const auto& id : ids) wait_for_state(*c, id, {"succeeded"});

  std::vector<std::string> seen;
  std::string token;
  int pages = 0;
  do {
    std::string path = "/v1/jobs?limit=2" + (token.empty() ? "" : "&page_token=" + token);
    const Json page = Json::parse(c->Get(path.c_str())->body);
    for (const auto& j : page["jobs"]) seen.push_back(j["id"]);
    token = page["next_page_token"].is_null() ? "" : page["next_page_token"].get<std::string>();
    ++pages;
  } while (!token.empty() && pages < 10);
  EXPECT_EQ(pages, 3);
  const std::vector<std::string> newest_first(ids.rbegin(), ids.rend());
  EXPECT_EQ(seen, newest_first);

  EXPECT_EQ(Json::parse(c->Get("/v1/jobs?state=succeeded")->body)["jobs"].size(), 5u);
  EXPECT_EQ(Json::parse(c->Get("/v1/jobs?state=queued")->body)["jobs"].size(), 0u);
  EXPECT_EQ(c->Get("/v1/jobs?state=bogus")->status, 400);
  EXPECT_EQ(c->Get("/v1/jobs?limit=0")->status, 400);
  EXPECT_EQ(c->Get("/v1/jobs?limit=101")->status, 400);
  EXPECT_EQ(c->Get("/v1/jobs?limit=100")->status, 200);
  EXPECT_EQ(c->Get("/v1/jobs?page_token=zz")->status, 400);
}

TEST(JobLifecycle, HealthReadinessMetricsAndOpenApi) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  EXPECT_EQ(c->Get("/healthz")->status, 200);
  EXPECT_EQ(c->Get("/readyz")->status, 200);
  const std::string id = submit(*c, tiny_scene(8, 8, 1));
  wait_for_state(*c, id, {"succeeded"});
  auto metrics = c->Get("/metrics");
  ASSERT_EQ(metrics->status, 200);
  EXPECT_NE(metrics->get_header_value("Content-Type").find("text/plain"), std::string::npos);
  const std::string& m = metrics->body;
  EXPECT_NE(m.find("penumbra_jobs{state=\"succeeded\"} 1"), std::string::npos) << m;
  EXPECT_NE(m.find("penumbra_queue_depth 0"), std::string::npos);
  EXPECT_NE(m.find("penumbra_render_seconds_count 1"), std::string::npos);
  EXPECT_NE(m.find("penumbra_rays_total"), std::string::npos);
  EXPECT_NE(m.find("penumbra_http_requests_total{method=\"POST\",route=\"/v1/jobs\",status=\"202\"} 1"),
            std::string::npos);
  EXPECT_NE(m.find("route=\"/v1/jobs/{id}\""), std::string::npos) << "route templates, not ids";
  EXPECT_EQ(m.find(id), std::string::npos) << "no per-job labels";

  auto openapi = c->Get("/v1/openapi.json");
  ASSERT_EQ(openapi->status, 200);
  const Json doc = Json::parse(openapi->body);
  EXPECT_EQ(doc["openapi"].get<std::string>().substr(0, 2), "3.");
  for (const char* path : {"/v1/jobs", "/v1/jobs/{id}", "/v1/jobs/{id}/result", "/v1/render", "/healthz",
                           "/readyz", "/metrics", "/v1/openapi.json"})
    EXPECT_TRUE(doc["paths"].contains(path)) << path;
}

}  // namespace
}  // namespace penumbra::test
