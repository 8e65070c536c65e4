#include "renderer/render/camera_sample.h"

#include <gtest/gtest.h>

#include <map>
#include <tuple>
#include <vector>

namespace penumbra::test {
namespace {

// With motion, a pixel's first 2^m samples of (time, film x, film y) form a (1, m, 3)-net: every
// elementary box of volume 2^-(m-1) holds two of them, so where a moving edge crosses a pixel
// the times are stratified within each part of the pixel, not paired with its positions at
// random. The sample takes exactly camera_sample_dimensions() dimensions, where CameraStage
// starts each path's first bounce.
TEST(CameraSample, TimeAndFilmPositionAreOne3DNet) {
  constexpr int m = 8, n = 1 << m;
  for (bool lens : {false, true}) {
    std::vector<vec3> pts;
    Sampler s(23);
    for (int i = 0; i < n; ++i) {
      s.start_pixel_sample(3, 5, uint32_t(i));
      const CameraSample c = take_camera_sample(s, lens, true);
      ASSERT_EQ(s.cursor().dimension, uint64_t(camera_sample_dimensions(lens, true)));
      ASSERT_GE(c.time, 0.f);
      ASSERT_LT(c.time, 1.f);
      if (!lens) ASSERT_EQ(c.lens, vec2(0.5f));
      pts.push_back(vec3(c.time, c.film.x, c.film.y));
    }
    for (int a = 0; a <= m - 1; ++a)
      for (int b = 0; a + b <= m - 1; ++b) {
        const int c = m - 1 - a - b;
        std::map<std::tuple<int, int, int>, int> boxes;
        for (const vec3& p : pts) ++boxes[{int(p.x * (1 << a)), int(p.y * (1 << b)), int(p.z * (1 << c))}];
        for (const auto& [box, count] : boxes) ASSERT_EQ(count, 2) << "lens " << lens << ", box " << a << " " << b << " " << c;
      }
  }
}

// Without motion the camera takes film then lens as 2D values, as before there was motion to
// pair: the images of scenes without motion do not change.
TEST(CameraSample, WithoutMotionFilmThenLens) {
  for (bool lens : {false, true}) {
    Sampler s(9), plain(9);
    for (uint32_t i = 0; i < 16; ++i) {
      s.start_pixel_sample(1, 2, i);
      plain.start_pixel_sample(1, 2, i);
      const CameraSample c = take_camera_sample(s, lens, false);
      EXPECT_EQ(c.film, plain.get_2d());
      EXPECT_EQ(c.lens, lens ? plain.get_2d() : vec2(0.5f));
      EXPECT_EQ(c.time, 0.f);
      EXPECT_EQ(s.cursor().dimension, plain.cursor().dimension);
    }
  }
}

}  // namespace
}  // namespace penumbra::test
