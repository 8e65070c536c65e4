// The light tree's choice per shading point (LightTree::choose_many), alone: nanoseconds per
// choice in chunks of points as a surface stage hands them over, on lights laid out as the
// accuracy scene many_lights (tests/accuracy/scenes/make_scenes.py: 48 ceiling panels and 16
// lamp spheres in a 4 x 3 x 16 m hall) with points on its floor and walls. For the walk's cost
// alone, side by side with another build (docs/performance.md, levers, session 44):
//
//   build/bench/light_tree_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "renderer/core/flush_denormals.h"
#include "renderer/lights/light_tree.h"

namespace {

using penumbra::LightBounds;
using penumbra::vec3;

std::vector<LightBounds> hall_lights() {
  std::vector<LightBounds> lights;
  for (int row = 0; row < 24; ++row) {
    const float z = 0.5f - 0.65f * float(row);
    for (float x : {-1.0f, 0.7f}) {
      LightBounds b;
      b.bounds.extend(vec3(x, 2.95f, z - 0.12f));
      b.bounds.extend(vec3(x + 0.3f, 2.95f, z));
      b.normals.axis = vec3(0.f, -1.f, 0.f);
      b.normals.cos_theta = 1.f;
      b.phi = 28.f * 0.036f / penumbra::kPi;
      lights.push_back(b);
    }
  }
  const float scales[3] = {0.5f, 1.f, 2.f}, colours[4] = {16.f, 20.f, 15.f, 30.f};
  for (int k = 0; k < 16; ++k) {
    const vec3 c(k % 2 == 0 ? -1.75f : 1.75f, 1.4f, 0.2f - 0.95f * float(k));
    LightBounds b;
    b.bounds.extend(c - vec3(0.06f));
    b.bounds.extend(c + vec3(0.06f));
    b.phi = colours[k % 4] * scales[k % 3] * 4.f * penumbra::kPi * 0.0036f / penumbra::kPi;
    lights.push_back(b);
  }
  return lights;
}

// Points on the floor (normal +y) and the two side walls (normals +x, -x), uniformly.
void hall_points(size_t n, std::vector<vec3>* p, std::vector<vec3>* normal, std::vector<float>* u) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.f, 1.f);
  for (size_t k = 0; k < n; ++k) {
    const int surface = int(k % 3);
    const float a = uni(rng), b = uni(rng);
    if (surface == 0) {
      p->push_back(vec3(-2.f + 4.f * a, 0.f, 1.f - 16.f * b));
      normal->push_back(vec3(0.f, 1.f, 0.f));
    } else {
      const float x = surface == 1 ? -2.f : 2.f;
      p->push_back(vec3(x, 3.f * a, 1.f - 16.f * b));
      normal->push_back(vec3(surface == 1 ? 1.f : -1.f, 0.f, 0.f));
    }
    u->push_back(uni(rng));
  }
}

void BM_ChooseMany(benchmark::State& state) {
  const std::vector<LightBounds> lights = hall_lights();
  std::vector<int> ids(lights.size());
  for (size_t k = 0; k < ids.size(); ++k) ids[k] = int(k);
  const penumbra::LightTree tree(lights, ids);
  const size_t chunk = size_t(state.range(0)), total = 64 * 1024;
  std::vector<vec3> p, normal;
  std::vector<float> u;
  hall_points(total, &p, &normal, &u);
  std::vector<int> light(total);
  std::vector<float> pmf(total);
  size_t at = 0;
  const penumbra::FlushDenormals flush_denormals;  // as the render threads run
  for (auto _ : state) {
    tree.choose_many(chunk, p.data() + at, normal.data() + at, u.data() + at, light.data() + at,
                     pmf.data() + at);
    benchmark::DoNotOptimize(light.data());
    at = at + 2 * chunk <= total ? at + chunk : 0;
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(chunk));
}
BENCHMARK(BM_ChooseMany)->Arg(64)->Arg(256);

}  // namespace

BENCHMARK_MAIN();
