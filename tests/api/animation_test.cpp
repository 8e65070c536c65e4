// "animation": parsing with JSON-pointer errors, frame shutters, choosing a frame, and the
// # pattern of per-frame file names.
#include <gtest/gtest.h>

#include "api/animation_parser.h"
#include "scene_test_util.h"

namespace penumbra::test {
namespace {

Json animated(const Json& animation) {
  Json s = base_scene();
  s["animation"] = animation;
  return s;
}

TEST(Animation, FrameShutterOpensAtFrameOverFps) {
  const Animation a{10, 40, 24.0, 0.5};
  const FrameShutter s = frame_shutter(a, 17);
  EXPECT_DOUBLE_EQ(s.open, 17.0 / 24.0);
  EXPECT_DOUBLE_EQ(s.close, 17.5 / 24.0);
  EXPECT_EQ(a.frame_count(), 31);
  EXPECT_DOUBLE_EQ(animation_time_extent(a), 40.5 / 24.0);
}

TEST(Animation, ParsedSceneStartsAtItsFirstFrame) {
  const LoadResult r = load(animated({{"frames", {3, 9}}, {"fps", 25}, {"shutter", 0.25}}));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  ASSERT_TRUE(r.request->animation);
  EXPECT_EQ(r.request->animation->first_frame, 3);
  EXPECT_EQ(r.request->animation->last_frame, 9);
  EXPECT_EQ(r.request->scene.camera.shutter_open, float(3.0 / 25.0));
  EXPECT_EQ(r.request->scene.camera.shutter_close, float(3.25 / 25.0));
}

TEST(Animation, DefaultsAre24FpsAndAHalfShutter) {
  const LoadResult r = load(animated({{"frames", {0, 1}}}));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(r.request->animation->fps, 24.0);
  EXPECT_EQ(r.request->animation->shutter, 0.5);
}

TEST(Animation, SelectFrameSetsTheShutterAndChecksTheRange) {
  LoadResult r = load(animated({{"frames", {1, 24}}, {"fps", 24}, {"shutter", 0.5}}));
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  Diagnostics diag;
  EXPECT_TRUE(select_frame(*r.request, 17, diag));
  EXPECT_EQ(r.request->scene.camera.shutter_open, float(17.0 / 24.0));
  EXPECT_EQ(r.request->scene.camera.shutter_close, float(17.5 / 24.0));
  EXPECT_FALSE(select_frame(*r.request, 25, diag, "--frame"));
  EXPECT_FALSE(select_frame(*r.request, 0, diag, "--frame"));
  const auto errors = diag.take_errors();
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].to_string(),
            "--frame (/animation/frames): frame 25 is outside the animation's frames [1, 24]");

  LoadResult still = load(base_scene());
  Diagnostics d2;
  EXPECT_FALSE(select_frame(*still.request, 1, d2, "--frame"));
  EXPECT_TRUE(has(d2.take_errors(), "", "no \"animation\""));
}

TEST(Animation, BadFieldsNameTheirPointer) {
  struct Case {
    Json animation;
    const char* pointer;
    const char* fragment;
  } cases[] = {
      {Json::array(), "/animation", "must be an object"},
      {{{"fps", 24}}, "/animation/frames", "required"},
      {{{"frames", {5, 2}}}, "/animation/frames", "start <= end"},
      {{{"frames", {1}}}, "/animation/frames", "2 integers"},
      {{{"frames", {1, 2.5}}}, "/animation/frames/1", "integer"},
      {{{"frames", {0, 2000000}}}, "/animation/frames/1", "must be in"},
      {{{"frames", {0, 200000}}}, "/animation/frames", "max_frames"},
      {{{"frames", {0, 1}}, {"fps", 0}}, "/animation/fps", "must be in (0, 1000]"},
      {{{"frames", {0, 1}}, {"fps", "24"}}, "/animation/fps", "number"},
      {{{"frames", {0, 1}}, {"shutter", 1.5}}, "/animation/shutter", "[0, 1]"},
      {{{"frames", {0, 1}}, {"shuter", 0.5}}, "/animation/shuter", "shutter"},
  };
  for (const Case& c : cases) {
    const LoadResult r = load(animated(c.animation));
    EXPECT_FALSE(r.ok()) << c.animation.dump();
    EXPECT_TRUE(has(r.errors, c.pointer, c.fragment)) << c.animation.dump() << "\n" << describe(r.errors);
  }
}

TEST(Animation, FrameLimitsHoldAtTheBoundary) {
  Limits limits;
  limits.max_frames = 10;
  limits.max_frame_number = 100;
  EXPECT_TRUE(load(animated({{"frames", {0, 9}}}), limits).ok());
  EXPECT_TRUE(has(load(animated({{"frames", {0, 10}}}), limits).errors, "/animation/frames",
                  "11 frames exceed the limit of 10 (max_frames)"));
  EXPECT_TRUE(load(animated({{"frames", {-100, -95}}}), limits).ok());
  EXPECT_TRUE(has(load(animated({{"frames", {-101, -95}}}), limits).errors, "/animation/frames/0"));
  EXPECT_TRUE(load(animated({{"frames", {95, 100}}}), limits).ok());
  EXPECT_TRUE(has(load(animated({{"frames", {95, 101}}}), limits).errors, "/animation/frames/1"));
}

TEST(Animation, ACameraShutterBesideAnAnimationIsAnError) {
  Json s = animated({{"frames", {0, 10}}});
  s["camera"]["shutter"] = {0, 1};
  const LoadResult r = load(s);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(has(r.errors, "/camera/shutter", "takes each frame's shutter")) << describe(r.errors);
}

// Motion must stay in range over every frame, not only the first one's shutter.
TEST(Animation, MotionIsCheckedOverEveryFrame) {
  Json s = animated({{"frames", {0, 24000}}, {"fps", 24}});
  s["objects"][0]["velocity"] = {1e16, 0, 0};
  const LoadResult r = load(s);
  EXPECT_FALSE(r.ok());
  Json near = animated({{"frames", {0, 1}}, {"fps", 24}});
  near["objects"][0]["velocity"] = {1e16, 0, 0};
  EXPECT_TRUE(load(near).ok());
}

TEST(Animation, FramePathReplacesHashRuns) {
  EXPECT_EQ(frame_path("out_####.exr", 17), "out_0017.exr");
  EXPECT_EQ(frame_path("out_#.exr", 1234), "out_1234.exr");
  EXPECT_EQ(frame_path("f##/img_###.png", 5), "f05/img_005.png");
  EXPECT_EQ(frame_path("out_####.exr", -3), "out_-0003.exr");
  EXPECT_EQ(frame_path("out.exr", 3), "out.exr");
  EXPECT_EQ(frame_path("#", INT64_MIN), "-9223372036854775808");
  EXPECT_TRUE(has_frame_pattern("a#.exr"));
  EXPECT_FALSE(has_frame_pattern("a.exr"));
}

}  // namespace
}  // namespace penumbra::test
