// Every limit at its boundary: the limit passes, limit + 1 fails.
#include <gtest/gtest.h>

#include <csignal>

#include "server_process.h"

namespace penumbra::test {
namespace {

int status_of(httplib::Client& c, const Json& scene) {
  auto res = post_json(c, "/v1/jobs", scene.dump());
  return res ? res->status : -1;
}

std::string first_pointer(httplib::Client& c, const Json& scene) {
  auto res = post_json(c, "/v1/jobs", scene.dump());
  if (!res || res->status != 422) return "";
  return Json::parse(res->body)["errors"][0]["pointer"];
}

// A flat mesh of `n` triangles (a fan in the floor plane).
Json with_triangles(Json scene, int n) {
  Json positions = Json::array({0.0, 0.01, 0.0});
  Json indices = Json::array();
  for (int i = 0; i <= n; ++i) {
    const double a = 0.1 * i;
    positions.push_back(0.5 * std::cos(a));
    positions.push_back(0.01);
    positions.push_back(0.5 * std::sin(a));
  }
  for (int i = 0; i < n; ++i) {
    indices.push_back(0);
    indices.push_back(i + 1);
    indices.push_back(i + 2);
  }
  scene["objects"].push_back({{"type", "mesh"}, {"material", "white"}, {"positions", positions}, {"indices", indices}});
  return scene;
}

// A scene whose only triangles are the mesh's (the Cornell box's quads would count too).
Json mesh_only_scene(int triangles) {
  Json scene = {{"version", 1},
                {"render", {{"width", 8}, {"height", 8}, {"spp", 1}}},
                {"camera", {{"position", {0, 1, 3}}, {"look_at", {0, 0, 0}}}},
                {"materials", {{"white", {{"type", "diffuse"}, {"color", {0.7, 0.7, 0.7}}}}}},
                {"objects", Json::array()},
                {"lights", {{{"type", "point"}, {"position", {0, 3, 0}}, {"intensity", {10, 10, 10}}}}}};
  return with_triangles(scene, triangles);
}

TEST(Limits, PixelsSppAndTrianglesAtTheBoundary) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-pixels", "256", "--max-spp", "4", "--max-triangles", "3"});
  auto c = server.client();
  EXPECT_EQ(status_of(*c, mesh_only_scene(3)), 202) << "3 triangles";
  const std::string p = first_pointer(*c, mesh_only_scene(4));
  EXPECT_NE(p.find("/indices"), std::string::npos) << p;
  server.signal(SIGKILL);
  server.wait_exit(std::chrono::seconds(5));

  TempDir dir2;
  ServerProcess server2(dir2.path(), {"--max-pixels", "256", "--max-spp", "4"});
  c = server2.client();
  EXPECT_EQ(status_of(*c, tiny_scene(16, 16, 1)), 202) << "256 pixels";
  EXPECT_EQ(status_of(*c, tiny_scene(257, 1, 1)), 422);
  EXPECT_EQ(first_pointer(*c, tiny_scene(257, 1, 1)), "/render");
  EXPECT_EQ(status_of(*c, tiny_scene(8, 8, 4)), 202) << "4 spp";
  EXPECT_EQ(first_pointer(*c, tiny_scene(8, 8, 5)), "/render/spp");
}

TEST(Limits, RenderTimePerJob) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-render-time", "1s"});
  auto c = server.client();
  Json at_limit = tiny_scene(8, 8, 1);
  at_limit["render"]["time_limit"] = 1.0;
  EXPECT_EQ(status_of(*c, at_limit), 202);
  Json over = tiny_scene(8, 8, 1);
  over["render"]["time_limit"] = 1.001;
  EXPECT_EQ(first_pointer(*c, over), "/render/time_limit");
  // A scene without a budget gets the server's: a long render stops at 1 s and keeps its image.
  const auto start = std::chrono::steady_clock::now();
  const std::string id = submit(*c, long_scene());
  const Json done = wait_for_state(*c, id, {"succeeded", "failed"}, std::chrono::seconds(30));
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_TRUE(done["stats"]["stopped_by_time_limit"].get<bool>());
  EXPECT_LT(done["stats"]["seconds"].get<double>(), 2.0);
  EXPECT_LT(elapsed, 10.0);
  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result").c_str())->status, 200);
}

TEST(Limits, QueueLengthAtTheBoundaryAnswers429WithRetryAfter) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-queue", "2"});
  auto c = server.client();
  const std::string running = submit(*c, long_scene());
  wait_for_state(*c, running, {"running"});
  const std::string q1 = submit(*c, tiny_scene(8, 8, 1));
  const std::string q2 = submit(*c, tiny_scene(8, 8, 1));
  EXPECT_EQ(get_job(*c, q1)["queue_position"], 0);
  EXPECT_EQ(get_job(*c, q2)["queue_position"], 1);
  auto full = post_json(*c, "/v1/jobs", tiny_scene(8, 8, 1).dump());
  ASSERT_TRUE(full);
  EXPECT_EQ(full->status, 429);
  EXPECT_EQ(Json::parse(full->body)["type"], "urn:penumbra:problem:queue-full");
  EXPECT_GE(std::stoi(full->get_header_value("Retry-After")), 1);
  // Cancelling one frees a place.
  EXPECT_EQ(c->Delete(("/v1/jobs/" + q2).c_str())->status, 200);
  EXPECT_EQ(status_of(*c, tiny_scene(8, 8, 1)), 202);
  EXPECT_EQ(c->Delete(("/v1/jobs/" + running).c_str())->status, 200);
}

}  // namespace
}  // namespace penumbra::test
