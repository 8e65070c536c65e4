// "render": {"outputs": [...]}: the output layers a scene asks for, checked with JSON pointers.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

LoadResult load_outputs(const Json& outputs) {
  Json scene = base_scene();
  scene["render"]["outputs"] = outputs;
  return load(scene);
}

TEST(RenderOutputs, NamesBecomeBitsInAnyOrder) {
  LoadResult r = load_outputs({"normal", "depth", "albedo"});
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.outputs, uint32_t(kOutputAlbedo | kOutputNormal | kOutputDepth));
  r = load_outputs(Json::array());
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.outputs, 0u);
  EXPECT_EQ(load(base_scene()).request->settings.outputs, 0u);
}

TEST(RenderOutputs, BadValuesNameTheirPointer) {
  EXPECT_TRUE(has(load_outputs("albedo").errors, "/render/outputs", "must be an array"));
  EXPECT_TRUE(has(load_outputs({1}).errors, "/render/outputs/0", "must be a string"));
  const LoadResult r = load_outputs({"albedo", "Normal", "albedo"});
  EXPECT_TRUE(has(r.errors, "/render/outputs/1", "unknown output layer 'Normal'")) << describe(r.errors);
  EXPECT_TRUE(has(r.errors, "/render/outputs/2", "listed twice")) << describe(r.errors);
  EXPECT_EQ(r.errors.size(), 2u) << describe(r.errors);
}

// A long array is refused by its length before any item is read (one error, not a million).
TEST(RenderOutputs, LengthIsBoundedBeforeItems) {
  const LoadResult r = load_outputs(Json(std::vector<std::string>(100000, "x")));
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].to_string(),
            "/render/outputs: 100000 outputs exceed the limit of 3 (the number of output layers)");
}

}  // namespace
}  // namespace penumbra::test
