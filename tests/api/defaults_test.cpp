// What a minimal scene gets when fields are left out, and the warning for an unlit scene.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(Defaults, RenderSettings) {
  const LoadResult r = load(base_scene());
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_TRUE(r.warnings.empty()) << describe(r.warnings);
  const RenderSettings& s = r.request->settings;
  EXPECT_EQ(s.width, 256);
  EXPECT_EQ(s.height, 256);
  EXPECT_EQ(s.spp, 64);
  EXPECT_EQ(s.max_depth, 8);
  EXPECT_EQ(s.rr_depth, 5);
  EXPECT_EQ(s.integrator, IntegratorKind::kPath);
  EXPECT_EQ(s.seed, 0u);
  EXPECT_EQ(s.noise_threshold, 0.f);
  EXPECT_EQ(s.time_limit, 0.0);
}

TEST(Defaults, ExplicitRenderSettings) {
  Json scene = base_scene();
  scene["render"] = Json::parse(R"({"width": 320, "height": 200, "spp": 16, "max_depth": 3,
    "rr_depth": 2, "integrator": "distributed", "seed": 7, "noise_threshold": 0.01,
    "time_limit": 2.5})");
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const RenderSettings& s = r.request->settings;
  EXPECT_EQ(s.width, 320);
  EXPECT_EQ(s.height, 200);
  EXPECT_EQ(s.spp, 16);
  EXPECT_EQ(s.max_depth, 3);
  EXPECT_EQ(s.rr_depth, 2);
  EXPECT_EQ(s.integrator, IntegratorKind::kDistributed);
  EXPECT_EQ(s.seed, 7u);
  EXPECT_FLOAT_EQ(s.noise_threshold, 0.01f);
  EXPECT_EQ(s.time_limit, 2.5);
}

TEST(Defaults, ObjectAndSceneDefaults) {
  Json scene = base_scene();
  scene["objects"][0].erase("emission");
  scene["environment"] = {{"radiance", {0.5, 0.5, 0.5}}};
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const ObjectDesc& o = r.request->scene.objects[0];
  EXPECT_EQ(o.emission, Spectrum(0));
  EXPECT_EQ(o.velocity, vec3(0));
  EXPECT_EQ(o.acceleration, vec3(0));
  EXPECT_EQ(r.request->scene.environment, Spectrum(0.5f));
  EXPECT_TRUE(r.request->scene.lights.empty());
}

TEST(Defaults, EmptySceneWithOnlyEnvironmentIsValid) {
  const LoadResult r = load_scene(R"({"version": 1,
    "camera": {"position": [0, 0, 1], "look_at": [0, 0, 0]},
    "environment": {"radiance": [1, 1, 1]}})");
  EXPECT_LOADS(r);
  EXPECT_TRUE(r.warnings.empty()) << describe(r.warnings);
}

TEST(Defaults, SceneWithoutEmitterWarnsOfABlackImage) {
  Json scene = base_scene();
  scene["objects"][0].erase("emission");
  scene["environment"] = {{"radiance", {0, 0, 0}}};
  scene["lights"] = Json::parse(R"([{"type": "point", "position": [0, 3, 0], "intensity": [0, 0, 0]}])");
  const LoadResult r = load(scene);
  EXPECT_LOADS(r);
  EXPECT_TRUE(has(r.warnings, "", "the image will be black")) << describe(r.warnings);
}

TEST(Defaults, LightsAreConverted) {
  Json scene = base_scene();
  scene["lights"] = Json::parse(R"([
    {"type": "point", "position": [1, 2, 3], "intensity": [5, 6, 7]},
    {"type": "directional", "direction": [0, -2, 0], "irradiance": [1, 2, 3]}])");
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& lights = r.request->scene.lights;
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(std::get<PointLightDesc>(lights[0]).position, vec3(1, 2, 3));
  EXPECT_EQ(std::get<PointLightDesc>(lights[0]).intensity, Spectrum(5, 6, 7));
  EXPECT_EQ(std::get<DirectionalLightDesc>(lights[1]).direction, vec3(0, -1, 0));  // normalised
  EXPECT_EQ(std::get<DirectionalLightDesc>(lights[1]).irradiance, Spectrum(1, 2, 3));
}

}  // namespace
}  // namespace penumbra::test
