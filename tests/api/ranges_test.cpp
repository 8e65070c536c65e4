// Numbers outside their ranges: negative, zero, huge, non-integral where integers are meant.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(Ranges, IntegersMustBeIntegral) {
  Json scene = base_scene();
  scene["render"] = {{"spp", 2.5}, {"width", 64.0}, {"height", 1e300}};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/render/spp", "must be an integer");
  EXPECT_FALSE(has(r.errors, "/render/width"));  // 64.0 is an integer (as in JSON Schema)
  EXPECT_ERROR(r, "/render/height", "must be an integer");
}

TEST(Ranges, RenderSettings) {
  Json scene = base_scene();
  scene["render"] = {{"width", 0},         {"height", -3},         {"spp", 0},
                     {"max_depth", 0},     {"rr_depth", 0},        {"noise_threshold", -0.1},
                     {"time_limit", -1}};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/render/width", "must be >= 1");
  EXPECT_ERROR(r, "/render/height", "must be >= 1");
  EXPECT_ERROR(r, "/render/spp", "must be >= 1");
  EXPECT_ERROR(r, "/render/max_depth", "must be >= 1, or -1 for unlimited");
  EXPECT_ERROR(r, "/render/rr_depth", "must be >= 1");
  EXPECT_ERROR(r, "/render/noise_threshold", "must be >= 0");
  EXPECT_ERROR(r, "/render/time_limit", "must be >= 0");
}

TEST(Ranges, MaxDepthMinusOneIsUnlimited) {
  Json scene = base_scene();
  scene["render"] = {{"max_depth", -1}};
  const LoadResult r = load(scene);
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.max_depth, -1);
  scene["render"]["max_depth"] = -2;
  EXPECT_ERROR(load(scene), "/render/max_depth", "-1 for unlimited");
}

TEST(Ranges, SeedTakesTheWholeUnsignedRange) {
  Json scene = base_scene();
  scene["render"] = {{"seed", 18446744073709551615ull}};
  const LoadResult r = load(scene);
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.seed, 18446744073709551615ull);
  scene["render"]["seed"] = 1.5;
  EXPECT_ERROR(load(scene), "/render/seed", "must be an integer");
}

TEST(Ranges, MaterialParameters) {
  Json scene = base_scene();
  scene["materials"] = Json::parse(R"({
    "d": {"type": "diffuse", "color": [1.01, 0, -0.1]},
    "c": {"type": "conductor", "color": [0.5, 0.5, 0.5], "roughness": 1.5},
    "g": {"type": "dielectric", "ior": 0, "roughness": -0.1, "absorption": [0, -1, 0]},
    "p": {"type": "plastic", "color": [0.5, 0.5, 0.5], "ior": -1.5, "roughness": 2}
  })");
  scene["objects"][0]["material"] = "d";
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/materials/d/color/0", "must be in [0, 1]");
  EXPECT_ERROR(r, "/materials/d/color/2", "must be in [0, 1]");
  EXPECT_ERROR(r, "/materials/c/roughness", "must be in [0, 1]");
  EXPECT_ERROR(r, "/materials/g/ior", "must be > 0");
  EXPECT_ERROR(r, "/materials/g/roughness", "must be in [0, 1]");
  EXPECT_ERROR(r, "/materials/g/absorption/1", "must be >= 0");
  EXPECT_ERROR(r, "/materials/p/ior", "must be > 0");
  EXPECT_ERROR(r, "/materials/p/roughness", "must be in [0, 1]");
}

TEST(Ranges, IorOfOneIsAllowed) {
  Json scene = base_scene();
  scene["materials"]["white"] = {{"type", "dielectric"}, {"ior", 1}};
  EXPECT_LOADS(load(scene));
}

TEST(Ranges, NegativeEmissionAndLights) {
  Json scene = base_scene();
  scene["objects"][0]["emission"] = {1, -1, 1};
  scene["environment"] = {{"radiance", {-0.1, 0, 0}}};
  scene["lights"] = Json::parse(R"([
    {"type": "point", "position": [0, 1, 0], "intensity": [1, 1, -1]},
    {"type": "directional", "direction": [0, 0, 0], "irradiance": [-1, 0, 0]}])");
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/0/emission/1", "must be >= 0");
  EXPECT_ERROR(r, "/environment/radiance/0", "must be >= 0");
  EXPECT_ERROR(r, "/lights/0/intensity/2", "must be >= 0");
  EXPECT_ERROR(r, "/lights/1/irradiance/0", "must be >= 0");
}

TEST(Ranges, ZeroDirectionAndRadius) {
  Json scene = base_scene();
  scene["objects"][0]["radius"] = 0;
  scene["lights"] = Json::parse(R"([{"type": "directional", "direction": [0, 0, 0], "irradiance": [1, 1, 1]}])");
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/0/radius", "must be > 0");
  EXPECT_ERROR(r, "/lights/0/direction", "must be a nonzero vector");
}

TEST(Ranges, HugeNumbersAreRejectedBeforeTheyOverflow) {
  Json scene = base_scene();
  scene["objects"][0]["emission"] = {1e31, 1, 1};      // beyond any float-safe magnitude
  scene["camera"]["position"] = {0, 0, 1e20};          // beyond world coordinates
  scene["render"] = {{"noise_threshold", 1e300}};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/0/emission/0", "magnitude <= 1e+30");
  EXPECT_ERROR(r, "/camera/position/2", "must be in [-1e+18, 1e+18]");
  EXPECT_ERROR(r, "/render/noise_threshold", "magnitude");
}

TEST(Ranges, LargeButRepresentableCoordinatesLoad) {
  Json scene = base_scene();
  scene["camera"] = {{"position", {1e6, 1e6, 1e6 + 5}}, {"look_at", {1e6, 1e6, 1e6}}};
  scene["objects"][0]["center"] = {1e6, 1e6, 1e6};
  EXPECT_LOADS(load(scene));
}

TEST(Ranges, TransformCannotOverflowWorldCoordinates) {
  Json scene = base_scene();
  scene["objects"][0]["center"] = {1e17, 0, 0};
  scene["objects"][0]["transform"] = {{"scale", 1e5}};
  EXPECT_ERROR(load(scene), "/objects/0/transform", "world-space coordinates");
}

TEST(Ranges, MotionCannotOverflowWithinTheShutter) {
  Json scene = base_scene();
  scene["camera"]["shutter"] = {0, 1e20};
  scene["objects"][0]["velocity"] = {1, 0, 0};
  EXPECT_ERROR(load(scene), "/objects/0/velocity", "within the shutter interval");
}

}  // namespace
}  // namespace penumbra::test
