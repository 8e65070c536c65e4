// A farm worker's scenes shared by its tasks (server/farm/scene_cache.h): one slot prepares a
// scene while the others wait for it, failures are not kept, a scene nobody holds is prepared
// again; and tiles rendered side by side from one prepared scene are the whole render's pixels.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "server/farm/farm_render.h"
#include "server/farm/scene_cache.h"
#include "tests/server/test_support.h"

namespace penumbra::test {
namespace {

using namespace penumbra::server;
using namespace std::chrono_literals;

std::shared_ptr<const PreparedScene> marked(int width) {
  auto p = std::make_shared<PreparedScene>();
  p->settings.width = width;
  return p;
}

// What `slots` threads asking the cache for "job" at once get.
std::vector<SceneCache::Lookup> get_from_slots(SceneCache& cache, int slots,
                                               const SceneCache::Prepare& prepare) {
  std::vector<SceneCache::Lookup> got(static_cast<std::size_t>(slots));
  std::vector<std::thread> threads;
  for (int i = 0; i < slots; ++i)
    threads.emplace_back([&, i] { got[size_t(i)] = cache.get("job", prepare); });
  for (auto& t : threads) t.join();
  return got;
}

TEST(SceneCache, OneSlotPreparesWhileTheOthersWait) {
  SceneCache cache;
  std::atomic<int> prepared{0};
  const auto prepare = [&](std::string&) {
    ++prepared;
    std::this_thread::sleep_for(50ms);  // long enough for every thread to ask meanwhile
    return marked(7);
  };
  const std::vector<SceneCache::Lookup> got = get_from_slots(cache, 4, prepare);
  EXPECT_EQ(prepared.load(), 1);
  int built = 0;
  for (const auto& g : got) {
    ASSERT_TRUE(g.scene);
    EXPECT_EQ(g.scene, got[0].scene);  // the same object, not copies
    EXPECT_TRUE(g.error.empty());
    built += g.reused ? 0 : 1;
  }
  EXPECT_EQ(built, 1);
  // Held: the next task reuses it.
  const auto again = cache.get("job", prepare);
  EXPECT_EQ(prepared.load(), 1);
  EXPECT_TRUE(again.reused);
  EXPECT_EQ(again.scene, got[0].scene);
}

TEST(SceneCache, ASceneNobodyHoldsIsPreparedAgain) {
  SceneCache cache;
  int prepared = 0;
  const auto prepare = [&](std::string&) {
    ++prepared;
    return marked(prepared);
  };
  auto first = cache.get("job", prepare);
  EXPECT_FALSE(first.reused);
  EXPECT_EQ(cache.live_entries(), 1u);
  first = {};
  EXPECT_EQ(cache.live_entries(), 0u);  // the cache itself does not keep it alive
  const auto second = cache.get("job", prepare);
  EXPECT_EQ(prepared, 2);
  EXPECT_FALSE(second.reused);
  EXPECT_EQ(second.scene->settings.width, 2);
}

TEST(SceneCache, KeysAreSeparateScenes) {
  SceneCache cache;
  int prepared = 0;
  const auto prepare = [&](std::string&) { return marked(++prepared); };
  const auto a = cache.get(scene_cache_key("job-a", std::nullopt), prepare);
  const auto b = cache.get(scene_cache_key("job-b", std::nullopt), prepare);
  const auto f1 = cache.get(scene_cache_key("job-a", 1), prepare);
  const auto f2 = cache.get(scene_cache_key("job-a", 2), prepare);
  EXPECT_EQ(prepared, 4);
  EXPECT_NE(a.scene, b.scene);
  EXPECT_NE(f1.scene, f2.scene);
  EXPECT_NE(a.scene, f1.scene);
  EXPECT_EQ(cache.live_entries(), 4u);
}

TEST(SceneCache, AFailureReachesTheWaitersAndIsNotKept) {
  SceneCache cache;
  std::atomic<int> prepared{0};
  const auto failing = [&](std::string& error) -> std::shared_ptr<const PreparedScene> {
    ++prepared;
    std::this_thread::sleep_for(50ms);
    error = "mesh.ply: not a PLY file";
    return nullptr;
  };
  const std::vector<SceneCache::Lookup> got = get_from_slots(cache, 3, failing);
  for (const auto& g : got) {
    EXPECT_FALSE(g.scene);
    EXPECT_FALSE(g.reused);
    EXPECT_EQ(g.error, "mesh.ply: not a PLY file");
  }
  EXPECT_EQ(cache.live_entries(), 0u);
  // The next task tries again, and may succeed.
  const auto retried = cache.get("job", [&](std::string&) { return marked(3); });
  ASSERT_TRUE(retried.scene);
  EXPECT_FALSE(retried.reused);
}

TEST(SceneCache, AThrowingPrepareFailsWithoutHangingItsWaiters) {
  SceneCache cache;
  const auto throwing = [&](std::string&) -> std::shared_ptr<const PreparedScene> {
    std::this_thread::sleep_for(50ms);
    throw std::runtime_error("out of memory");
  };
  const std::vector<SceneCache::Lookup> got = get_from_slots(cache, 3, throwing);
  for (const auto& g : got) {
    EXPECT_FALSE(g.scene);
    EXPECT_EQ(g.error, "out of memory");
  }
  EXPECT_EQ(cache.live_entries(), 0u);
}

// Two tiles rendered at the same time from one prepared scene are, to the bit, the pixels of
// the whole frame rendered from a scene of its own.
TEST(FarmPiece, TilesFromOneSharedSceneAreTheWholeRendersPixels) {
  Json scene = tiny_scene(24, 16, 4);
  scene["render"]["outputs"] = Json::array({"albedo", "depth"});
  const std::string text = scene.dump();
  RenderJobOptions options;
  options.threads = 1;
  std::string error;
  const auto prepared = prepare_piece_scene(text, options, TaskPiece{}, error);
  ASSERT_TRUE(prepared) << error;

  JobRuntime whole_runtime;
  std::string load_error;
  api::LoadResult loaded = load_job_request(text, options, load_error);
  ASSERT_TRUE(loaded.ok()) << load_error;
  const RenderOutcome whole =
      render_request(*loaded.request, options, options.started, whole_runtime, {});
  ASSERT_EQ(whole.kind, RenderOutcome::Kind::kSucceeded) << whole.error;

  const PixelWindow windows[2] = {{0, 0, 13, 16}, {13, 0, 24, 16}};
  RenderOutcome tiles[2];
  JobRuntime runtimes[2];
  std::thread a([&] {
    tiles[0] = render_farm_piece(*prepared, true, options, runtimes[0], TaskPiece{{}, windows[0]});
  });
  std::thread b([&] {
    tiles[1] = render_farm_piece(*prepared, false, options, runtimes[1], TaskPiece{{}, windows[1]});
  });
  a.join();
  b.join();
  for (int k = 0; k < 2; ++k) {
    const RenderOutcome& t = tiles[k];
    ASSERT_EQ(t.kind, RenderOutcome::Kind::kSucceeded) << t.error;
    const PixelWindow& w = windows[k];
    ASSERT_EQ(t.image.width, w.x1 - w.x0);
    ASSERT_EQ(t.image.height, w.y1 - w.y0);
    ASSERT_EQ(t.layers.size(), whole.layers.size());
    for (int y = w.y0; y < w.y1; ++y)
      for (int x = w.x0; x < w.x1; ++x)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(t.image.pixel(x - w.x0, y - w.y0)[c], whole.image.pixel(x, y)[c])
              << "tile " << k << " pixel " << x << "," << y;
    for (std::size_t l = 0; l < whole.layers.size(); ++l) {
      const ImageLayer &tl = t.layers[l], &wl = whole.layers[l];
      ASSERT_EQ(tl.name, wl.name);
      const int n = wl.channels;
      for (int y = w.y0; y < w.y1; ++y)
        for (int x = w.x0; x < w.x1; ++x)
          for (int c = 0; c < n; ++c)
            ASSERT_EQ(tl.data[(std::size_t(y - w.y0) * w.width() + (x - w.x0)) * n + c],
                      wl.data[(std::size_t(y) * 24 + x) * n + c])
                << wl.name << " of tile " << k << " pixel " << x << "," << y;
    }
    ASSERT_TRUE(t.scene_reused.has_value());
    EXPECT_EQ(*t.scene_reused, k == 1);
    EXPECT_EQ(t.build_seconds > 0, k == 0);  // a reused scene took no build
  }
}

}  // namespace
}  // namespace penumbra::test
