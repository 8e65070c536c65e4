// The rough plastic's coating tables are shared within a scene build and kept by nothing after
// it: a long-running service that renders many distinct plastics does not grow.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "renderer/materials/coating_tables.h"
#include "renderer/materials/plastic.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

SceneInput plastics_scene(int first, int count) {
  SceneInput in;
  in.camera.position = vec3(0.f, 0.f, 3.f);
  in.environment = Spectrum(1.f);
  for (int i = 0; i < count; ++i) {
    // Distinct (roughness, ior) pairs across calls.
    const float r = 0.05f + 0.9f * float((first + i) % 97) / 97.f;
    const float ior = 1.2f + 0.01f * float((first + i) / 97);
    in.materials.push_back(PlasticParams{Spectrum(0.5f), ior, r});
    ObjectDesc o;
    o.shape = SphereDesc{vec3(float(i) - 0.5f * float(count), 0.f, 0.f), 0.4f};
    o.material = uint32_t(i);
    in.objects.push_back(o);
  }
  return in;
}

TEST(CoatingTables, ManyDistinctRoughPlasticsLeaveNothingBehind) {
  const int64_t before = coating_tables_alive();
  for (int scene = 0; scene < 24; ++scene) {
    const RenderResult r = render_input(plastics_scene(5 * scene, 5), small_settings(8, 8, 1, 3));
    ASSERT_EQ(r.stats.nonfinite_samples, 0u);
    EXPECT_EQ(coating_tables_alive(), before) << "after scene " << scene;
  }
}

TEST(CoatingTables, SharedWithinABuild) {
  CoatingTableCache cache;
  const PlasticParams a{Spectrum(0.2f), 1.5f, 0.3f}, b{Spectrum(0.9f), 1.5f, 0.3f}, c{Spectrum(0.2f), 1.6f, 0.3f};
  const Material ma(a, &cache), mb(b, &cache), mc(c, &cache);
  EXPECT_EQ(cache.size(), 2u);  // a and b share a coating, c has its own ior
  // Through the cache or alone, the same material.
  const Material alone(a);
  const vec3 wi = glm::normalize(vec3(0.3f, 0.1f, 0.9f)), wo = glm::normalize(vec3(-0.4f, 0.2f, 0.8f));
  EXPECT_EQ(ma.eval(BsdfContext{}, wi, wo), alone.eval(BsdfContext{}, wi, wo));
  EXPECT_NE(ma.eval(BsdfContext{}, wi, wo), mc.eval(BsdfContext{}, wi, wo));
}

// The interval lookup of square nodes (a guess from sqrt(mu), then corrected) answers what the
// bisection over the stored nodes answers, at the nodes themselves, next to them and between.
TEST(CoatingTables, SquareNodeIntervalsAreTheBisections) {
  const CoatingTables tables = make_coating_tables(false, GgxDistribution(0.3f), 1.5f);
  ASSERT_TRUE(tables.square_nodes);
  CoatingTables bisected = tables;
  bisected.square_nodes = false;
  std::vector<float> mus = {0.f, 1.f, 0.5f, 1e-9f};
  for (int i = 0; i < tables.nodes; ++i) {
    const float c = tables.cosines[i];
    mus.insert(mus.end(), {c, std::nextafter(c, 0.f), std::nextafter(c, 2.f)});
  }
  for (int k = 0; k <= 100000; ++k) mus.push_back(float(k) / 100000.f);
  for (float mu : mus) {
    if (mu < 0.f || mu > 1.f) continue;
    ASSERT_EQ(tables.interval(mu), bisected.interval(mu)) << mu;
  }
  // Adaptive nodes (ior below 1) are never square.
  EXPECT_FALSE(make_coating_tables(false, GgxDistribution(0.3f), 0.7f).square_nodes);
  // What plastics read: the scene's cached copy, which must keep the shortcut.
  CoatingTableCache cache;
  EXPECT_TRUE(cache.get(false, GgxDistribution(0.3f), 1.5f).square_nodes);
}

}  // namespace
}  // namespace penumbra::test
