// How a farm job is cut into tasks (server/farm/farm_tasks.h): the tiles of a large still cover
// every pixel once and are close to square; what the submission asks decides tiles or frames.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "server/farm/farm_tasks.h"
#include "server/server_config.h"

namespace penumbra::test {
namespace {

using namespace penumbra::server;

// Every pixel of the frame in exactly one window.
bool covers_once(const std::vector<PixelWindow>& tiles, int width, int height) {
  std::vector<int> hits(std::size_t(width) * height, 0);
  for (const PixelWindow& t : tiles) {
    if (!t.fits(width, height)) return false;
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) ++hits[std::size_t(y) * width + x];
  }
  for (int h : hits)
    if (h != 1) return false;
  return true;
}

TEST(FarmTiles, AFrameOfAtMostTilePixelsIsOneTask) {
  EXPECT_TRUE(tile_windows(256, 256, 65536).empty());
  EXPECT_TRUE(tile_windows(64, 64, 65536).empty());
  EXPECT_EQ(tile_windows(257, 256, 65536).size(), 2u);
}

TEST(FarmTiles, TheDefaultCutsA1024FrameIn16SquareTiles) {
  const auto tiles = tile_windows(1024, 1024, ServerConfig{}.tile_pixels);
  ASSERT_EQ(tiles.size(), 16u);
  for (const PixelWindow& t : tiles) {
    EXPECT_EQ(t.width(), 256);
    EXPECT_EQ(t.height(), 256);
  }
  EXPECT_TRUE(covers_once(tiles, 1024, 1024));
}

TEST(FarmTiles, OddSizesAreCoveredOnceByNearlySquareTiles) {
  for (const auto& [w, h, n] : std::vector<std::tuple<int, int, int64_t>>{
           {1920, 1080, 65536}, {1000, 7, 4096}, {7, 1000, 4096}, {333, 777, 5000},
           {4096, 64, 4096}, {101, 103, 4096}}) {
    const auto tiles = tile_windows(w, h, n);
    ASSERT_FALSE(tiles.empty()) << w << "x" << h;
    EXPECT_TRUE(covers_once(tiles, w, h)) << w << "x" << h;
    const int64_t wanted = (int64_t(w) * h + n - 1) / n;
    EXPECT_GE(int64_t(tiles.size()), wanted) << w << "x" << h;
    EXPECT_LE(int64_t(tiles.size()), 2 * wanted + 2) << w << "x" << h;
    // Close to square unless the frame is thinner than a square tile.
    const int side = int(std::sqrt(double(n)));
    if (w >= side && h >= side)
      for (const PixelWindow& t : tiles) {
        const double aspect = double(t.width()) / t.height();
        EXPECT_GT(aspect, 0.5) << w << "x" << h;
        EXPECT_LT(aspect, 2.0) << w << "x" << h;
      }
  }
  const auto wide = tile_windows(1920, 1080, 65536);
  EXPECT_EQ(wide.size(), 32u);  // 8 columns of 240, 4 rows of 270
}

TEST(FarmTiles, ParamsRoundTrip) {
  const TaskPiece tile{std::nullopt, PixelWindow{256, 512, 512, 768}};
  const TaskPiece back = task_piece_from_params(task_params_json(tile));
  ASSERT_TRUE(back.window);
  EXPECT_EQ(*back.window, *tile.window);
  EXPECT_FALSE(back.frame);
  EXPECT_EQ(task_params_json(tile), R"({"window":[256,512,512,768]})");
  const TaskPiece frame = task_piece_from_params(R"({"frame": 17})");
  EXPECT_EQ(frame.frame, 17);
  EXPECT_FALSE(frame.window);
  EXPECT_FALSE(task_piece_from_params("{}").frame);
  EXPECT_FALSE(task_piece_from_params("not json").window);
  EXPECT_FALSE(task_piece_from_params(R"({"window": [1, 2, 3]})").window);
}

TEST(FarmTiles, TheSubmissionDecidesFramesOrTiles) {
  const JobShape still = read_job_shape(R"({"render": {"width": 2048, "height": 2048}})", 64);
  EXPECT_FALSE(still.frames);
  EXPECT_TRUE(still.splittable);
  const JobShape anim = read_job_shape(
      R"({"scene": {"animation": {"frames": [3, 50], "fps": 24}}, "assets": {}})", 64);
  ASSERT_TRUE(anim.frames);
  EXPECT_EQ(anim.frames->first, 3);
  EXPECT_EQ(anim.frames->second, 50);
  EXPECT_FALSE(read_job_shape(R"({"render": {"window": [0, 0, 8, 8]}})", 64).splittable);
  EXPECT_FALSE(read_job_shape(R"({"render": {"time_limit": 5}})", 64).splittable);
  EXPECT_TRUE(read_job_shape(R"({"render": {"time_limit": 0}})", 64).splittable);
  EXPECT_FALSE(read_job_shape(R"({"render": {"path_reuse": 2}})", 64).splittable);
  EXPECT_TRUE(read_job_shape(R"({"render": {"path_reuse": 1}})", 64).splittable);
}

TEST(FarmConfigTiles, TilePixelsFlagAndEnvironment) {
  const auto parse = [](std::vector<std::string> args, std::map<std::string, std::string> env) {
    return parse_server_config(args, [&](const char* name) -> const char* {
      const auto it = env.find(name);
      return it == env.end() ? nullptr : it->second.c_str();
    });
  };
  EXPECT_EQ(parse({}, {}).config->tile_pixels, 65536);
  EXPECT_EQ(parse({"--tile-pixels", "250000"}, {}).config->tile_pixels, 250000);
  EXPECT_EQ(parse({}, {{"PENUMBRA_TILE_PIXELS", "10000"}}).config->tile_pixels, 10000);
  EXPECT_FALSE(parse({"--tile-pixels", "100"}, {}).config);  // at least 4096 (64x64)
}

}  // namespace
}  // namespace penumbra::test
