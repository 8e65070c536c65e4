// Animations through the render service (issue #13; docs/animation-and-windows.md, "In the
// render service"): an animation job renders every frame, each equal bit for bit to
// `penumbra render --frame N`; progress counts frames; a kill -9 mid-animation keeps the finished
// frames and does not render them again; GET /v1/jobs/{id}/frames.tar holds every frame, byte
// for byte the per-frame results; bad frame parameters answer problem JSON naming `frame`.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/statvfs.h>

#include <csignal>
#include <cstdlib>
#include <map>
#include <set>

#include "renderer/io/image_io.h"
#include "notify_support.h"
#include "server_process.h"

namespace penumbra::test {
namespace {

// A Cornell box with its glass sphere thrown across the room (velocity and gravity), so every
// frame differs from the others and has motion blur; `first`..`last` rendered.
Json animation_scene(int first, int last, int size, int spp) {
  Json scene = tiny_scene(size, size, spp);
  for (Json& object : scene["objects"])
    if (object["type"] == "sphere") {
      object["velocity"] = {0.6, 0.3, 0};
      object["acceleration"] = {0, -0.5, 0};
    }
  scene["animation"] = {{"frames", {first, last}}, {"fps", 24}, {"shutter", 0.5}};
  return scene;
}

std::string write_temp(const TempDir& dir, const std::string& name, const std::string& bytes) {
  const std::string path = dir.path() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

Image decode(const TempDir& dir, const std::string& name, const std::string& bytes) {
  return read_image_file(write_temp(dir, name, bytes));
}

// `penumbra render SCENE --frame N -o OUT` on this machine, the reference of each frame.
Image render_frame_with_cli(const TempDir& dir, const std::string& scene_path, int frame) {
  const std::string out = dir.path() + "/cli_" + std::to_string(frame) + ".exr";
  const std::string cmd = std::string(PENUMBRA_BINARY) + " render --quiet " + scene_path +
                          " --frame " + std::to_string(frame) + " -o " + out + " 2>&1";
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
  return read_image_file(out);
}

std::string frame_path(const std::string& id, int frame, const std::string& format) {
  return "/v1/jobs/" + id + "/result?frame=" + std::to_string(frame) + "&format=" + format;
}

// The members of a ustar archive by name, checked block by block (header checksum, sizes,
// padding, two closing zero blocks).
std::vector<std::pair<std::string, std::string>> untar(const std::string& tar) {
  std::vector<std::pair<std::string, std::string>> files;
  std::size_t at = 0;
  for (;;) {
    if (at + 512 > tar.size()) throw std::runtime_error("tar: truncated at " + std::to_string(at));
    const std::string header = tar.substr(at, 512);
    if (header == std::string(512, '\0')) {
      if (tar.substr(at + 512) != std::string(512, '\0')) throw std::runtime_error("tar: bad end");
      return files;
    }
    if (header.compare(257, 5, "ustar") != 0) throw std::runtime_error("tar: no ustar magic");
    unsigned sum = 0;
    for (std::size_t i = 0; i < 512; ++i)
      sum += (i >= 148 && i < 156) ? unsigned(' ') : static_cast<unsigned char>(header[i]);
    if (sum != std::stoul(header.substr(148, 7), nullptr, 8))
      throw std::runtime_error("tar: bad checksum");
    const std::string name = header.substr(0, header.find('\0'));
    const std::size_t size = std::stoull(header.substr(124, 11), nullptr, 8);
    files.emplace_back(name, tar.substr(at + 512, size));
    at += 512 + (size + 511) / 512 * 512;
  }
}

Json problem(const httplib::Result& res) { return Json::parse(res->body); }

// Frames [1, 6], 24 x 24 pixels at 16 spp: every frame over HTTP (EXR) equals the command line's
// render of the same frame, pixel for pixel, bit for bit; the PNG and the archive agree.
TEST(AnimationJobs, EveryFrameEqualsTheCommandLineRenderBitForBit) {
  TempDir dir;
  ServerProcess server(dir.path() + "/data");
  auto c = server.client();
  const Json scene = animation_scene(1, 6, 24, 16);
  const std::string scene_path = write_temp(dir, "anim.json", scene.dump());
  const std::string id = submit(*c, scene);
  const Json job = wait_for_state(*c, id, {"succeeded", "failed"}, std::chrono::seconds(120));
  ASSERT_EQ(job["state"], "succeeded") << job.dump();
  EXPECT_EQ(job["frames"], (Json{{"first", 1}, {"last", 6}, {"done", 6}}));
  EXPECT_EQ(job["progress"], 1.0);
  EXPECT_EQ(job["samples_total"], 24 * 24 * 16 * 6);
  EXPECT_EQ(job["stats"]["frames_rendered"], 6);
  EXPECT_EQ(job["links"]["frames"], "/v1/jobs/" + id + "/frames.tar");
  std::vector<float> first_frame;
  for (int frame = 1; frame <= 6; ++frame) {
    auto res = c->Get(frame_path(id, frame, "exr").c_str());
    ASSERT_EQ(res->status, 200) << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "image/x-exr");
    EXPECT_EQ(res->get_header_value("Penumbra-Frame"), std::to_string(frame));
    EXPECT_NE(res->get_header_value("Content-Disposition").find("frame_000" + std::to_string(frame) + ".exr"),
              std::string::npos)
        << res->get_header_value("Content-Disposition");
    const Image served = decode(dir, "served.exr", res->body);
    const Image reference = render_frame_with_cli(dir, scene_path, frame);
    ASSERT_EQ(served.width, 24);
    ASSERT_EQ(served.height, 24);
    EXPECT_TRUE(served.rgb == reference.rgb) << "frame " << frame << " differs from the CLI's";
    if (frame == 1) first_frame = served.rgb;
    if (frame > 1) {
      EXPECT_FALSE(served.rgb == first_frame) << "frame " << frame << " = frame 1";
    }
    auto png = c->Get(frame_path(id, frame, "png").c_str());
    ASSERT_EQ(png->status, 200);
    EXPECT_EQ(png->get_header_value("Content-Type"), "image/png");
  }
  // Without ?frame the result is the first frame, as for a client that knows no animations.
  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/result?format=exr").c_str())->body,
            c->Get(frame_path(id, 1, "exr").c_str())->body);
}

// The archive: frame_0001.exr ... frame_0006.exr, each byte for byte the per-frame result; the
// PNG archive likewise; a Range of it is the same bytes as that slice of the whole.
TEST(AnimationJobs, ArchiveHoldsEveryFrameByteIdentical) {
  TempDir dir;
  ServerProcess server(dir.path());
  auto c = server.client();
  const std::string id = submit(*c, animation_scene(1, 6, 16, 4));
  ASSERT_EQ(wait_for_state(*c, id, {"succeeded", "failed"}, std::chrono::seconds(120))["state"],
            "succeeded");
  for (const std::string format : {"exr", "png"}) {
    auto res = c->Get(("/v1/jobs/" + id + "/frames.tar?format=" + format).c_str());
    ASSERT_EQ(res->status, 200) << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/x-tar");
    EXPECT_EQ(res->get_header_value("Content-Disposition"),
              "attachment; filename=\"" + id + ".frames." + format + ".tar\"");
    EXPECT_EQ(res->get_header_value("Content-Length"), std::to_string(res->body.size()));
    const auto files = untar(res->body);
    ASSERT_EQ(files.size(), 6u);
    for (int frame = 1; frame <= 6; ++frame) {
      EXPECT_EQ(files[frame - 1].first, "frame_000" + std::to_string(frame) + "." + format);
      const auto single = c->Get(frame_path(id, frame, format).c_str());
      EXPECT_TRUE(files[frame - 1].second == single->body) << format << " frame " << frame;
    }
    // A resumed download: bytes 1000.. of the archive are the same bytes.
    auto part = c->Get(("/v1/jobs/" + id + "/frames.tar?format=" + format).c_str(),
                       {{"Range", "bytes=1000-"}});
    ASSERT_EQ(part->status, 206);
    EXPECT_TRUE(part->body == res->body.substr(1000));
  }
  // The default is EXR.
  EXPECT_EQ(untar(c->Get(("/v1/jobs/" + id + "/frames.tar").c_str())->body)[0].first,
            "frame_0001.exr");
}

// While an animation renders, frames.done counts finished frames and progress lies between
// done/6 and (done+1)/6, never going back; finished frames are served while later ones render.
TEST(AnimationJobs, ProgressCountsFrames) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--render-threads", "1"});
  auto c = server.client();
  const std::string id = submit(*c, animation_scene(1, 6, 48, 256));
  double last_progress = 0;
  int last_done = 0;
  std::set<int> seen_done;
  bool served_while_running = false, preview_seen = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
  for (;;) {
    const Json job = get_job(*c, id);
    ASSERT_NE(job["state"], "failed") << job.dump();
    if (job["state"] == "succeeded") break;
    ASSERT_LT(std::chrono::steady_clock::now(), deadline);
    if (job["state"] == "running") {
      const int done = job["frames"]["done"];
      const double progress = job["progress"];
      EXPECT_GE(done, last_done);
      EXPECT_GE(progress + 1e-12, last_progress);
      EXPECT_GE(progress + 1e-9, done / 6.0) << job.dump();
      EXPECT_LE(progress, (done + 1) / 6.0 + 1e-9) << job.dump();
      if (done < 6) {
        EXPECT_EQ(job["frames"]["current"], 1 + done) << job.dump();
        const double current = job["frames"]["current_progress"];
        EXPECT_NEAR(progress, (done + current) / 6.0, 1e-9);
      } else {
        // Every frame rendered, the job not yet marked succeeded (its last frame's files and the
        // archive being written): no frame under way.
        EXPECT_FALSE(job["frames"].contains("current")) << job.dump();
      }
      EXPECT_EQ(job["samples_total"], 48 * 48 * 256 * 6);
      seen_done.insert(done);
      last_done = done;
      last_progress = progress;
      if (done >= 1 && done < 6) {
        EXPECT_EQ(c->Get(frame_path(id, done, "png").c_str())->status, 200);
        const auto next = c->Get(frame_path(id, done + 1, "png").c_str());
        if (next->status == 404) {
          EXPECT_EQ(problem(next)["errors"][0]["parameter"], "frame");
          EXPECT_TRUE(next->has_header("Retry-After"));
        }
        served_while_running = true;
        auto preview = c->Get(("/v1/jobs/" + id + "/result?preview=true&format=png").c_str());
        if (preview->status == 200 && preview->has_header("Penumbra-Frame")) {
          EXPECT_GE(std::stoi(preview->get_header_value("Penumbra-Frame")), done + 1);
          preview_seen = true;
        }
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_GE(seen_done.size(), 3u) << "frames finished one after another";
  EXPECT_TRUE(served_while_running);
  EXPECT_TRUE(preview_seen);
}

// The event stream of an animation: an event as each frame finishes (frames.done 1, 2, ... 6, in
// order), and progress samples in between naming the frame under way and how far it is.
TEST(AnimationJobs, EventsCarryProgressPerFrame) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--render-threads", "1"});
  auto c = server.client();
  // Frames of 0.75 s each, whatever the renderer's speed (a time budget per frame, samples
  // without end): progress is sampled at most 4 times a second, so a shorter frame may pass
  // between two samples. (With 512 spp instead, frames meant to last 0.7 s took 0.2 s once the
  // renderer got faster, and the test failed now and then.)
  Json scene = animation_scene(1, 6, 32, 1 << 16);
  scene["render"]["time_limit"] = 0.75;
  const std::string id = submit(*c, scene);
  const StreamRead r = read_events(server, id);
  ASSERT_EQ(r.status, 200);
  ASSERT_FALSE(r.events.empty());
  EXPECT_EQ(r.events.back().event, "succeeded");
  std::vector<int> done_seen;
  int progress_samples = 0;
  double last_progress = 0;
  for (const SseEvent& e : r.events) {
    ASSERT_TRUE(e.data.contains("frames")) << e.data.dump();
    const int done = e.data["frames"]["done"];
    if (done_seen.empty() || done_seen.back() != done) done_seen.push_back(done);
    const double progress = e.data["progress"];
    EXPECT_GE(progress + 1e-12, last_progress) << e.data.dump();
    last_progress = progress;
    if (e.event == "running" && e.data["frames"].contains("current")) {
      EXPECT_EQ(e.data["frames"]["current"], 1 + done);
      const double current = e.data["frames"]["current_progress"];
      EXPECT_NEAR(progress, (done + current) / 6.0, 1e-9) << e.data.dump();
      if (current > 0 && current < 1) ++progress_samples;
    }
  }
  EXPECT_EQ(done_seen, (std::vector<int>{0, 1, 2, 3, 4, 5, 6})) << r.text.substr(0, 2000);
  EXPECT_GE(progress_samples, 1) << "no progress sample within a frame";
}

ino_t inode_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? st.st_ino : 0;
}

// kill -9 in the middle of an animation: after the restart the job resumes at the first
// unfinished frame. The finished frames' files are the same files (never rewritten), the stats
// say which frame the second attempt started from, and every frame is served at the end.
TEST(AnimationJobs, KillDashNineKeepsFinishedFramesAndResumes) {
  TempDir dir;
  std::string id;
  int done_at_kill = 0;
  std::map<int, ino_t> inodes;
  const std::string frames_dir = dir.path() + "/results/";
  {
    ServerProcess server(dir.path(), {"--render-threads", "1"});
    auto c = server.client();
    id = submit(*c, animation_scene(1, 6, 48, 256));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    for (;;) {
      const Json job = get_job(*c, id);
      ASSERT_TRUE(job["state"] == "queued" || job["state"] == "running") << job.dump();
      done_at_kill = job["frames"]["done"];
      if (done_at_kill >= 2) break;
      ASSERT_LT(std::chrono::steady_clock::now(), deadline);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    server.signal(SIGKILL);
    ASSERT_EQ(server.wait_exit(std::chrono::seconds(5)), 128 + SIGKILL);
  }
  ASSERT_LT(done_at_kill, 6) << "the kill came too late to test a resume";
  for (int frame = 1; frame <= done_at_kill; ++frame) {
    inodes[frame] = inode_of(frames_dir + id + ".frames/" + std::to_string(frame) + ".exr");
    ASSERT_NE(inodes[frame], 0u) << "frame " << frame << " counted done has no file";
  }
  ServerProcess server(dir.path(), {"--render-threads", "1"});
  auto c = server.client();
  const Json job = wait_for_state(*c, id, {"succeeded", "failed"}, std::chrono::seconds(180));
  ASSERT_EQ(job["state"], "succeeded") << job.dump();
  EXPECT_EQ(job["attempts"], 2);
  EXPECT_EQ(job["frames"]["done"], 6);
  // The second attempt started at the first frame not committed done: the frames the first
  // attempt finished (at most the one whose commit was under way at the kill excepted).
  const int resumed_from = job["stats"]["first_frame_rendered"].get<int>();
  EXPECT_GE(resumed_from, done_at_kill) << job.dump();
  EXPECT_GT(resumed_from, 1) << "resumed from the start: " << job.dump();
  EXPECT_EQ(job["stats"]["frames_rendered"], 7 - resumed_from) << job.dump();
  for (const auto& [frame, inode] : inodes) {
    if (frame < resumed_from) {
      EXPECT_EQ(inode_of(frames_dir + id + ".frames/" + std::to_string(frame) + ".exr"), inode)
          << "frame " << frame << " was rendered again";
    }
  }
  for (int frame = 1; frame <= 6; ++frame)
    EXPECT_EQ(c->Get(frame_path(id, frame, "exr").c_str())->status, 200) << frame;
  EXPECT_EQ(untar(c->Get(("/v1/jobs/" + id + "/frames.tar").c_str())->body).size(), 6u);
}

// Bad frame parameters: problem JSON naming `frame` (or /animation/frames for a scene beyond
// --max-frames); the archive of a still is a 404.
TEST(AnimationJobs, BadFrameParametersNameTheParameter) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-frames", "8"});
  auto c = server.client();
  const std::string anim = submit(*c, animation_scene(3, 5, 8, 1));
  const std::string still = submit(*c, tiny_scene(8, 8, 1));
  ASSERT_EQ(wait_for_state(*c, anim, {"succeeded"})["state"], "succeeded");
  ASSERT_EQ(wait_for_state(*c, still, {"succeeded"})["state"], "succeeded");
  const auto expect_problem = [&](const std::string& path, int status, const std::string& type) {
    auto res = c->Get(path.c_str());
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, status) << path << " " << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json") << path;
    const Json p = problem(res);
    EXPECT_EQ(p["type"], "urn:penumbra:problem:" + type) << path << " " << p.dump();
    EXPECT_EQ(p["errors"][0]["parameter"], "frame") << path << " " << p.dump();
    EXPECT_NE(p["detail"].get<std::string>().find("frame"), std::string::npos);
  };
  const std::string base = "/v1/jobs/" + anim + "/result?frame=";
  for (const char* bad : {"abc", "", "1.5", "3x", "+3", "99999999", "-"})
    expect_problem(base + bad, 400, "invalid-parameter");
  expect_problem(base + "2", 404, "frame-not-available");  // before the first
  expect_problem(base + "6", 404, "frame-not-available");  // after the last
  expect_problem(base + "-4", 404, "frame-not-available");
  expect_problem("/v1/jobs/" + still + "/result?frame=1", 422, "not-an-animation");
  for (int frame = 3; frame <= 5; ++frame)
    EXPECT_EQ(c->Get((base + std::to_string(frame)).c_str())->status, 200) << frame;
  // A layer the scene did not ask for, of a finished frame: the layer's 404.
  auto layer = c->Get((base + "4&layer=albedo").c_str());
  EXPECT_EQ(layer->status, 404);
  EXPECT_EQ(problem(layer)["type"], "urn:penumbra:problem:layer-not-rendered");
  // The archive of a still does not exist.
  auto tar = c->Get(("/v1/jobs/" + still + "/frames.tar").c_str());
  EXPECT_EQ(tar->status, 404);
  EXPECT_EQ(problem(tar)["type"], "urn:penumbra:problem:not-an-animation");
  // More frames than --max-frames: 422 at /animation/frames. Exactly the limit is accepted.
  auto over = post_json(*c, "/v1/jobs", animation_scene(1, 9, 8, 1).dump());
  ASSERT_EQ(over->status, 422) << over->body;
  EXPECT_EQ(problem(over)["errors"][0]["pointer"], "/animation/frames") << over->body;
  EXPECT_EQ(post_json(*c, "/v1/jobs", animation_scene(1, 8, 8, 1).dump())->status, 202);
}

// The disk space check (507) counts every frame: an animation whose frames would not fit is
// refused before anything is written, though one of its frames alone would fit, and a short
// animation of the same frames is accepted.
TEST(AnimationJobs, DiskSpaceCheckCountsEveryFrame) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-frames", "100000"});
  auto c = server.client();
  struct statvfs fs {};
  ASSERT_EQ(::statvfs(dir.path().c_str(), &fs), 0);
  const double available = double(fs.f_bavail) * double(fs.f_frsize);
  // A 4096^2 frame's worst case is its float EXR and 8-bit PNG: more than 20 bytes a pixel.
  const double frame_bytes = 4096.0 * 4096.0 * 20.0;
  const int frames = int(available / frame_bytes) + 2;
  ASSERT_LT(frames, 100000) << "the disk is too large for this test";
  ASSERT_GT(available, 3 * frame_bytes + (64 << 20)) << "the disk is too full for this test";
  const auto cancel_if_accepted = [&](const httplib::Result& res) {
    if (res && res->status == 202) c->Delete(("/v1/jobs/" + problem(res)["id"].get<std::string>()).c_str());
  };
  auto big = post_json(*c, "/v1/jobs", animation_scene(1, frames, 4096, 1).dump());
  ASSERT_TRUE(big);
  cancel_if_accepted(big);
  ASSERT_EQ(big->status, 507) << big->body;
  const Json p = problem(big);
  EXPECT_EQ(p["type"], "urn:penumbra:problem:insufficient-storage");
  EXPECT_GT(p["bytes_needed"].get<double>(), frames * frame_bytes) << p.dump();
  auto small = post_json(*c, "/v1/jobs", animation_scene(1, 2, 4096, 1).dump());
  ASSERT_TRUE(small);
  cancel_if_accepted(small);
  EXPECT_EQ(small->status, 202) << small->body;
}

}  // namespace
}  // namespace penumbra::test
