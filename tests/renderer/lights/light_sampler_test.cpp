// The light sampler chooses lights half by power, half uniformly; lights sample themselves.
#include <gtest/gtest.h>

#include <random>

#include "renderer/lights/area_light.h"
#include "renderer/lights/directional_light.h"
#include "renderer/lights/environment_light.h"
#include "renderer/lights/light_sampler.h"
#include "renderer/lights/point_light.h"
#include "renderer/render/light_kernels.h"
#include "renderer/sampling/sampling.h"
#include "renderer/shapes/quad.h"

namespace penumbra::test {
namespace {

TEST(LightSampler, ChoosesHalfByPowerHalfUniformly) {
  const LightSampler sampler({1.f, 3.f, 0.f, 4.f});
  const float expected[4] = {0.5f * 1.f / 8.f + 0.125f, 0.5f * 3.f / 8.f + 0.125f, 0.125f,
                             0.5f * 4.f / 8.f + 0.125f};
  int counts[4] = {0, 0, 0, 0};
  const int n = 400000;
  for (int i = 0; i < n; ++i) ++counts[sampler.choose((float(i) + 0.5f) / float(n))];
  for (int i = 0; i < 4; ++i) {
    EXPECT_FLOAT_EQ(sampler.pmf(i), expected[i]) << i;
    EXPECT_NEAR(double(counts[i]) / n, expected[i], 1e-4) << i;
  }
}

TEST(LightSampler, NonFiniteOrNegativePowerCountsAsZero) {
  const LightSampler sampler({INFINITY, -1.f, NAN, 2.f});
  EXPECT_FLOAT_EQ(sampler.pmf(3), 0.5f + 0.125f);
  for (int i = 0; i < 3; ++i) EXPECT_FLOAT_EQ(sampler.pmf(i), 0.125f);
  EXPECT_EQ(sampler.choose(0.99999994f), 3);
  EXPECT_TRUE(LightSampler().empty());
}

// Lights left out of a sampler (the path integrator's, Scene::mis_light_sampler) keep their
// index with pmf 0 and are never chosen, wherever they sit: first, between, or last (where the
// cdf's rounding to 1 must not hand them the top of [0, 1)); the choice in SIMD
// (choose_lights: a count of cdf <= u) agrees.
TEST(LightSampler, LeftOutLightsAreNeverChosen) {
  const std::vector<float> powers = {2.f, 1.f, 5.f, 3.f, 7.f};
  const std::vector<bool> sampled = {false, true, false, true, false};
  const LightSampler sampler(powers, sampled);
  ASSERT_FALSE(sampler.empty());
  EXPECT_FLOAT_EQ(sampler.pmf(1), 0.5f * 1.f / 4.f + 0.25f);
  EXPECT_FLOAT_EQ(sampler.pmf(3), 0.5f * 3.f / 4.f + 0.25f);
  for (int i : {0, 2, 4}) EXPECT_EQ(sampler.pmf(i), 0.f) << i;
  const int n = 100000;
  int counts[5] = {0, 0, 0, 0, 0};
  std::vector<float> us;
  for (int i = 0; i < n; ++i) us.push_back(float(i) / float(n));
  us.push_back(0.99999994f);
  for (float u : us) {
    const int light = sampler.choose(u);
    ++counts[light];
    int32_t simd;
    choose_lights(sampler.cdf().data(), int32_t(sampler.cdf().size()), 1, &u, &simd);
    EXPECT_EQ(simd, light) << u;
  }
  EXPECT_EQ(counts[0] + counts[2] + counts[4], 0);
  EXPECT_NEAR(double(counts[1]) / n, sampler.pmf(1), 1e-4);

  const LightSampler none(powers, std::vector<bool>(powers.size(), false));
  EXPECT_TRUE(none.empty());
  for (int i = 0; i < 5; ++i) EXPECT_EQ(none.pmf(i), 0.f);
}

TEST(Lights, PointLightFallsOffWithTheSquareOfTheDistance) {
  const PointLight light(vec3(0.f, 2.f, 0.f), Spectrum(8.f));
  LightSample ls;
  ASSERT_TRUE(light.sample(vec3(0.f), 0.f, vec2(0.5f), &ls));
  EXPECT_TRUE(ls.is_delta);
  EXPECT_EQ(ls.value, Spectrum(2.f));
  EXPECT_EQ(ls.wi, vec3(0.f, 1.f, 0.f));
  EXPECT_FLOAT_EQ(ls.distance, 2.f);
  EXPECT_FLOAT_EQ(light.power(1.f), 4.f * kPi * 8.f);
}

TEST(Lights, DirectionalLightArrivesAgainstItsDirection) {
  const DirectionalLight light(vec3(0.f, -2.f, 0.f), Spectrum(3.f));
  LightSample ls;
  ASSERT_TRUE(light.sample(vec3(5.f), 0.f, vec2(0.5f), &ls));
  EXPECT_EQ(ls.wi, vec3(0.f, 1.f, 0.f));
  EXPECT_TRUE(std::isinf(ls.distance));
  EXPECT_EQ(ls.value, Spectrum(3.f));
}

// The irradiance from a constant environment onto an upward surface is pi L: the estimator
// L cos / pdf over the environment's own samples must give it.
TEST(Lights, ConstantEnvironmentIrradianceIsPiL) {
  const ConstantEnvironment env(Spectrum(0.5f));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
  double sum = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    ASSERT_TRUE(env.sample(vec3(0.f), 0.f, {u01(rng), u01(rng)}, &ls));
    EXPECT_FLOAT_EQ(ls.pdf, env.pdf(ls.wi));
    sum += std::max(0.f, ls.wi.y) * ls.value.x / ls.pdf;
  }
  EXPECT_NEAR(sum / n, kPi * 0.5, 0.01);
}

// An area light emits from its front side only and samples through its shape.
TEST(Lights, AreaLightEmitsFromTheFrontOnly) {
  const Quad quad(QuadDesc{vec3(-0.5f, 1.f, -0.5f), vec3(1, 0, 0), vec3(0, 0, 1)}, ShapeContext{});
  const AreaLight light(quad, Spectrum(2.f));  // front: cross(u, v) = -y, facing down
  LightSample ls;
  EXPECT_TRUE(light.sample(vec3(0.f), 0.f, vec2(0.3f, 0.6f), &ls));
  EXPECT_EQ(ls.value, Spectrum(2.f));
  EXPECT_FLOAT_EQ(ls.pdf, light.pdf(vec3(0.f), ls.p, ls.n, 0.f));
  EXPECT_FALSE(light.sample(vec3(0.f, 2.f, 0.f), 0.f, vec2(0.3f, 0.6f), &ls));
  EXPECT_FLOAT_EQ(light.power(1.f), 2.f * 1.f * kPi);
}

}  // namespace
}  // namespace penumbra::test
