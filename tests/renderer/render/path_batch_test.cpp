// PathBatch (renderer/render/wavefront_integrator.h): the wavefront driver's batch keeps its
// per-path arrays at their capacity and assigns each camera sample in place; a batch handed more
// samples than its capacity grows, and integrates them exactly as a batch with room for all.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "renderer/render/wavefront_integrator.h"
#include "renderer/scene/scene.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

// One camera sample into `batch`: a run of one (PathBatch takes its samples as runs).
void add_sample(PathBatch& batch, const Ray& ray, Sampler* sampler, const Sampler::Cursor& cursor) {
  const float* const arrays[6] = {&ray.origin.x,    &ray.origin.y,    &ray.origin.z,
                                  &ray.direction.x, &ray.direction.y, &ray.direction.z};
  batch.add_camera_run(1, arrays, &ray.time, sampler, cursor.index, cursor.dimension);
}

// A furnace's light grey diffuse ball over a coloured floor: a path's radiance depends on the
// directions its sampler gives (between ball and floor it bounces, some paths several times), so
// two batches that handed a path other sampler values would differ.
SceneInput ball_over_floor() {
  SceneInput in = furnace_with_sphere(DiffuseParams{Spectrum(0.9f)});
  in.materials.push_back(DiffuseParams{Spectrum(0.5f, 0.4f, 0.3f)});
  in.objects.push_back(
      quad_object(vec3(-6.f, -1.f, 6.f), vec3(12.f, 0.f, 0.f), vec3(0.f, 0.f, -12.f), 1));
  return in;
}

// The radiance of `count` camera rays through ball_over_floor's ball and past it, integrated in
// a batch of room `capacity`.
// With `warm_up`, the batch first integrates that many paths (and so makes its surface stages
// and their queues at its first capacity) and is cleared.
std::vector<Spectrum> integrate_rays(const Scene& scene, size_t capacity, size_t count,
                                     size_t warm_up = 0) {
  PathBatch batch(capacity, /*record_first_hits=*/false);
  const IntegrateBatchFn integrate = select_generic_batch_integrator(IntegratorKind::kPath);
  std::vector<Sampler> samplers(count, Sampler(7));
  if (warm_up > 0) {
    Sampler other(3);
    other.start_pixel_sample(99, 0, 0);
    for (size_t i = 0; i < warm_up; ++i)
      add_sample(batch, Ray{vec3(0.f, 0.f, 4.f), vec3(0.f, 0.f, -1.f), 0.f}, &other,
                 Sampler::Cursor{uint32_t(i), 2});
    PathCounters counters;
    integrate(scene, IntegratorSettings{}, batch, counters);
    batch.clear();
  }
  for (size_t i = 0; i < count; ++i) {
    samplers[i].start_pixel_sample(int(i), 0, 0);
    // Rays from the camera's place towards points spread over the ball's face and past it.
    const float x = -1.2f + 2.4f * float(i) / float(count);
    const vec3 origin(0.f, 0.f, 4.f);
    const Ray ray{origin, glm::normalize(vec3(x, 0.3f * x, 0.f) - origin), 0.f};
    add_sample(batch, ray, &samplers[i], Sampler::Cursor{0, 2});
  }
  EXPECT_EQ(batch.size(), count);
  PathCounters counters;
  integrate(scene, IntegratorSettings{}, batch, counters);
  std::vector<Spectrum> out;
  for (size_t i = 0; i < batch.size(); ++i) out.push_back(batch.radiance(i));
  return out;
}

TEST(PathBatch, GrowsPastItsCapacityAndIntegratesAsALargerOne) {
  const auto scene = Scene::build(ball_over_floor());
  constexpr size_t kCount = 37;
  const std::vector<Spectrum> roomy = integrate_rays(*scene, 64, kCount);
  const std::vector<Spectrum> grown = integrate_rays(*scene, 2, kCount);  // grows 2 -> 64
  // Grown after a first batch made the stages' queues at the first capacity.
  const std::vector<Spectrum> grown_later = integrate_rays(*scene, 2, kCount, 2);
  ASSERT_EQ(roomy.size(), kCount);
  ASSERT_EQ(grown.size(), kCount);
  ASSERT_EQ(grown_later.size(), kCount);
  int lit = 0;
  for (size_t i = 0; i < kCount; ++i) {
    EXPECT_EQ(std::memcmp(&roomy[i], &grown[i], sizeof(Spectrum)), 0) << "path " << i;
    EXPECT_EQ(std::memcmp(&roomy[i], &grown_later[i], sizeof(Spectrum)), 0) << "path " << i;
    lit += roomy[i].x > 0.f;
  }
  EXPECT_EQ(lit, int(kCount));  // every path sees the environment, directly or off the ball
}

// A camera stage's runs (one pixel's consecutive samples, their rays from arrays) are the paths
// the same samples added one by one, as runs of one, give, also where a run is longer than
// the room left and the batch must grow more than once for it.
TEST(PathBatch, CameraRunsAreThePathsAddedOneByOne) {
  const auto scene = Scene::build(ball_over_floor());
  const IntegrateBatchFn integrate = select_generic_batch_integrator(IntegratorKind::kPath);
  const uint32_t runs[2][2] = {{3, 5}, {11, 4}};  // first sample, count
  Sampler samplers[2] = {Sampler(9), Sampler(9)};
  std::vector<float> rays[2][6], times[2];
  for (int r = 0; r < 2; ++r) {
    samplers[r].start_pixel_sample(5 + r, 2, runs[r][0]);
    for (uint32_t j = 0; j < runs[r][1]; ++j) {
      const float x = -0.9f + 0.45f * float(j) + 0.1f * float(r);
      const vec3 origin(0.01f * float(j), 0.f, 4.f);
      const vec3 d = glm::normalize(vec3(x, 0.2f * x, 0.f) - origin);
      for (int c = 0; c < 3; ++c) {
        rays[r][c].push_back(origin[c]);
        rays[r][3 + c].push_back(d[c]);
      }
      times[r].push_back(0.f);
    }
  }
  // by_run grows three times for its first run (1 -> 8) and once for the second (16).
  PathBatch by_run(1, false), one_by_one(64, false);
  for (int r = 0; r < 2; ++r) {
    const float* const arrays[6] = {rays[r][0].data(), rays[r][1].data(), rays[r][2].data(),
                                    rays[r][3].data(), rays[r][4].data(), rays[r][5].data()};
    by_run.add_camera_run(runs[r][1], arrays, times[r].data(), &samplers[r], runs[r][0], 2);
    for (uint32_t j = 0; j < runs[r][1]; ++j)
      add_sample(one_by_one,
                 Ray{vec3(rays[r][0][j], rays[r][1][j], rays[r][2][j]),
                     vec3(rays[r][3][j], rays[r][4][j], rays[r][5][j]), times[r][j]},
                 &samplers[r], Sampler::Cursor{runs[r][0] + j, 2});
  }
  ASSERT_EQ(by_run.size(), 9u);
  ASSERT_EQ(one_by_one.size(), 9u);
  PathCounters counters;
  integrate(*scene, IntegratorSettings{}, by_run, counters);
  integrate(*scene, IntegratorSettings{}, one_by_one, counters);
  int lit = 0;
  for (size_t i = 0; i < 9; ++i) {
    EXPECT_EQ(std::memcmp(&by_run.radiance(i), &one_by_one.radiance(i), sizeof(Spectrum)), 0)
        << "path " << i;
    lit += one_by_one.radiance(i).x > 0.f;
  }
  EXPECT_EQ(lit, 9);
}

TEST(PathBatch, ClearedBatchTakesNewPathsInPlace) {
  MaterialParams white;
  const auto scene = Scene::build(furnace_with_sphere(white));
  PathBatch batch(4, false);
  Sampler sampler(1);
  sampler.start_pixel_sample(0, 0, 0);
  const Ray away{vec3(0.f, 0.f, 4.f), vec3(0.f, 0.f, 1.f), 0.f};  // escapes: radiance 1
  for (int i = 0; i < 4; ++i) add_sample(batch, away, &sampler, Sampler::Cursor{0, 2});
  EXPECT_TRUE(batch.full());
  PathCounters counters;
  const IntegrateBatchFn integrate = select_generic_batch_integrator(IntegratorKind::kPath);
  integrate(*scene, IntegratorSettings{}, batch, counters);
  EXPECT_EQ(batch.radiance(3).y, 1.f);
  batch.clear();
  EXPECT_EQ(batch.size(), 0u);
  // A path added after clear starts afresh: no radiance or throughput left from the last one.
  const Ray at_ball{vec3(0.f, 0.f, 4.f), vec3(0.f, 0.f, -1.f), 0.f};
  add_sample(batch, at_ball, &sampler, Sampler::Cursor{0, 2});
  integrate(*scene, IntegratorSettings{}, batch, counters);
  ASSERT_EQ(batch.size(), 1u);
  EXPECT_GT(batch.radiance(0).y, 0.f);
  EXPECT_LE(batch.radiance(0).y, 1.f);  // a white ball in a white furnace: at most 1
}

}  // namespace
}  // namespace penumbra::test
