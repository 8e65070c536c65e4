// The rough plastic's coating tables are shared within a scene build and between builds through a
// bounded process-wide cache: a long-running service that renders many distinct plastics grows no
// further than the bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include "renderer/materials/coating_tables.h"
#include "renderer/materials/coating_tables_integrals.h"
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

// A bound small enough that the scenes below overflow it, restored whatever the test's outcome.
class SmallLru {
 public:
  explicit SmallLru(size_t capacity) : old_(set_coating_table_lru_capacity(capacity)) {
    clear_coating_table_lru();
  }
  ~SmallLru() {
    set_coating_table_lru_capacity(old_);
    clear_coating_table_lru();
  }

 private:
  size_t old_;
};

TEST(CoatingTables, ManyDistinctRoughPlasticsKeepNoMoreThanTheBound) {
  constexpr size_t kBound = 8;
  const SmallLru small(kBound);
  const int64_t before = coating_tables_alive();
  for (int scene = 0; scene < 24; ++scene) {  // 120 distinct coatings
    const RenderResult r = render_input(plastics_scene(5 * scene, 5), small_settings(8, 8, 1, 3));
    ASSERT_EQ(r.stats.nonfinite_samples, 0u);
    EXPECT_LE(coating_tables_alive(), before + int64_t(kBound)) << "after scene " << scene;
    EXPECT_EQ(coating_table_lru_size(), std::min(kBound, size_t(5 * (scene + 1))))
        << "after scene " << scene;
  }
  clear_coating_table_lru();
  EXPECT_EQ(coating_tables_alive(), before);
}

// A service renders the same materials again and again: the second build of a scene computes
// nothing and shares the first one's tables.
TEST(CoatingTables, SharedBetweenBuilds) {
  const SmallLru small(kCoatingTableLruCapacity);
  const PlasticParams p{Spectrum(0.5f), 1.5f, 0.3f};
  CoatingTableCache first, second;
  const CoatingTables& a = PlasticBsdf::tables_for(p, first);
  const int64_t alive = coating_tables_alive();
  const CoatingTables& b = PlasticBsdf::tables_for(p, second);
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(coating_tables_alive(), alive);
  EXPECT_EQ(coating_table_lru_size(), 1u);
}

// Least recently used out; a scene's cache keeps its tables alive after the process-wide cache
// has dropped them.
TEST(CoatingTables, LeastRecentlyUsedIsEvicted) {
  const SmallLru small(2);
  const GgxDistribution d(0.3f);
  const auto a = shared_coating_tables(false, d, 1.5f);
  const auto b = shared_coating_tables(false, d, 1.6f);
  EXPECT_EQ(shared_coating_tables(false, d, 1.5f), a);   // a is now the most recent
  const auto c = shared_coating_tables(false, d, 1.7f);  // evicts b
  EXPECT_EQ(coating_table_lru_size(), 2u);
  EXPECT_EQ(shared_coating_tables(false, d, 1.5f), a);
  EXPECT_EQ(shared_coating_tables(false, d, 1.7f), c);
  EXPECT_NE(shared_coating_tables(false, d, 1.6f), b);  // recomputed: a new object
  // The key: smooth coatings ignore alpha, rough ones do not.
  EXPECT_EQ(shared_coating_tables(true, GgxDistribution(0.2f), 1.5f),
            shared_coating_tables(true, GgxDistribution(0.4f), 1.5f));
  EXPECT_NE(shared_coating_tables(false, GgxDistribution(0.2f), 1.5f),
            shared_coating_tables(false, GgxDistribution(0.4f), 1.5f));
  // A scene's cache holds its tables whatever the process-wide cache evicts.
  CoatingTableCache scene;
  const CoatingTables& held = scene.get(false, GgxDistribution(0.5f), 1.4f);
  const float t = held.transmittance[10];
  clear_coating_table_lru();
  EXPECT_EQ(coating_table_lru_size(), 0u);
  EXPECT_EQ(&scene.get(false, GgxDistribution(0.5f), 1.4f), &held);
  EXPECT_EQ(held.transmittance[10], t);
}

// Many threads asking for overlapping coatings at once: one table per key in the end, the bound
// kept, every answer the same numbers as a fresh computation.
TEST(CoatingTables, ConcurrentLookupsAgree) {
  const SmallLru small(4);
  const CoatingTables fresh = make_coating_tables(false, GgxDistribution(0.25f), 1.45f);
  std::vector<std::thread> threads;
  std::vector<int> mismatches(8, 0);
  for (int k = 0; k < 8; ++k) {
    threads.emplace_back([k, &fresh, &mismatches] {
      for (int i = 0; i < 12; ++i) {
        const float eta = 1.45f + 0.05f * float((k + i) % 6);
        const auto t = shared_coating_tables(false, GgxDistribution(0.25f), eta);
        if (eta == 1.45f && (t->transmittance != fresh.transmittance ||
                             t->internal_reflectance != fresh.internal_reflectance))
          ++mismatches[size_t(k)];
      }
    });
  }
  for (auto& t : threads) t.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
  EXPECT_LE(coating_table_lru_size(), 4u);
}

// The coating's integrals with the rule's direction-free part hoisted are the generic ones
// (microfacet.h) to the bit, so the tables and every image stay what they were.
TEST(CoatingTables, HoistedIntegralsAreTheGenericOnesExactly) {
  for (float alpha : {1e-4f, 0.01f, 0.0225f, 0.09f, 0.25f, 0.49f, 1.f}) {
    const GgxDistribution d(alpha);
    for (float eta : {1.f / 3.f, 0.6f, 1.f / 1.5f, 0.99f, 1.f, 1.01f, 1.33f, 1.5f, 1.6f, 3.f}) {
      for (int k = 0; k <= 20; ++k) {
        float mu = float(k) / 20.f;
        mu = k == 0 ? 0.f : mu * mu;
        ASSERT_EQ(coating_reflectance(d, mu, eta), rough_dielectric_reflectance(d, mu, eta))
            << alpha << " " << eta << " " << mu;
        ASSERT_EQ(coating_transmittance(d, mu, eta), rough_dielectric_transmittance(d, mu, eta))
            << alpha << " " << eta << " " << mu;
      }
    }
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
