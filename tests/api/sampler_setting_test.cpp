// render.sampler (api/scene_parser.cpp): "auto" resolved from the scene alone (correlated
// multi-jittered points for a uniform render of a power-of-two spp, Sobol points otherwise, with
// adaptive sampling or the scene's own time budget), explicit choices, and errors that name the
// field.
#include "api/render_overrides.h"
#include "tests/api/scene_test_util.h"

#include <vector>

namespace penumbra::test {
namespace {

SamplerKind sampler_of(const Json& render) {
  Json scene = base_scene();
  scene["render"] = render;
  const LoadResult r = load(scene);
  EXPECT_TRUE(r.ok()) << describe(r.errors);
  return r.ok() ? r.request->settings.sampler : SamplerKind::kSobol;
}

TEST(SamplerSetting, AutoIsCmjForAUniformRenderAndSobolWhenTheCountIsDecidedLater) {
  EXPECT_EQ(sampler_of(Json::object()), SamplerKind::kCorrelatedMultiJitter);
  EXPECT_EQ(sampler_of({{"spp", 128}}), SamplerKind::kCorrelatedMultiJitter);
  EXPECT_EQ(sampler_of({{"spp", 1}}), SamplerKind::kCorrelatedMultiJitter);
  EXPECT_EQ(sampler_of({{"spp", 100}}), SamplerKind::kSobol);  // not a power of two
  EXPECT_EQ(sampler_of({{"sampler", "auto"}}), SamplerKind::kCorrelatedMultiJitter);
  EXPECT_EQ(sampler_of({{"noise_threshold", 0.05}}), SamplerKind::kSobol);
  EXPECT_EQ(sampler_of({{"time_limit", 2.0}}), SamplerKind::kSobol);
  EXPECT_EQ(sampler_of({{"sampler", "auto"}, {"time_limit", 2.0}}), SamplerKind::kSobol);
}

TEST(SamplerSetting, ExplicitChoices) {
  EXPECT_EQ(sampler_of({{"sampler", "sobol"}}), SamplerKind::kSobol);
  EXPECT_EQ(sampler_of({{"sampler", "cmj"}}), SamplerKind::kCorrelatedMultiJitter);
  // A budget that may cut the render short: the user's call.
  EXPECT_EQ(sampler_of({{"sampler", "cmj"}, {"time_limit", 2.0}}), SamplerKind::kCorrelatedMultiJitter);
  EXPECT_EQ(sampler_of({{"sampler", "sobol"}, {"noise_threshold", 0.05}}), SamplerKind::kSobol);
}

TEST(SamplerSetting, ErrorsNameTheField) {
  Json scene = base_scene();
  scene["render"] = {{"sampler", "cmj"}, {"noise_threshold", 0.05}};
  EXPECT_ERROR(load(scene), "/render/sampler", "adaptive sampling");
  scene["render"] = {{"sampler", "cmj"}, {"spp", 100}};
  EXPECT_ERROR(load(scene), "/render/sampler", "power of two (100 is not)");
  scene["render"] = {{"sampler", "sobl"}};
  EXPECT_ERROR(load(scene), "/render/sampler", "did you mean 'sobol'");
  scene["render"] = {{"sampler", 3}};
  EXPECT_ERROR(load(scene), "/render/sampler", "string");
}

TEST(SamplerSetting, TheCommandLineFlagSetsIt) {
  const std::vector<RenderOverride> sobol = {{"--sampler", "sobol"}}, budget = {{"--time-limit", "5"}};
  const LoadResult r = load_scene(base_scene().dump(), {}, sobol);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(r.request->settings.sampler, SamplerKind::kSobol);
  // And a time budget given on the command line resolves "auto" as the scene's own would.
  const LoadResult t = load_scene(base_scene().dump(), {}, budget);
  ASSERT_TRUE(t.ok()) << describe(t.errors);
  EXPECT_EQ(t.request->settings.sampler, SamplerKind::kSobol);
}

}  // namespace
}  // namespace penumbra::test
