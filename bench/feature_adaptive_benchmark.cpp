// Adaptive sampling (render.noise_threshold) against uniform sampling on the accuracy scenes:
// the rays and seconds each needs to reach the same relMSE against the Mitsuba 3 reference.
//
//   build/bench/feature_adaptive_benchmark [--seeds N] [SCENE...]
//     > docs/adaptive_sampling.csv 2> docs/adaptive_sampling.md
//
// (run from the repository root; default: every scene of tests/accuracy/scenes, 4 seeds, 2
// threads). For each scene it renders a uniform ladder (16..1024 spp) and adaptive renders
// (cap 1024 spp, thresholds 0.1, 0.05, 0.03), each averaged over the seeds, and prints one CSV row
// per configuration; the markdown table on stderr gives, for each adaptive render, the rays and
// seconds uniform sampling needs for the same relMSE (log-log interpolation of its ladder), the
// ratios (< 1: adaptive is cheaper) and the scene's Neyman bound (the best ratio possible). Rays traced is the machine-independent cost; seconds are
// wall time on a shared machine.
// relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 1e-2).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/io/image_io.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"

namespace {

double rel_mse(const penumbra::Image& img, const penumbra::Image& ref) {
  double sum = 0.0;
  for (size_t i = 0; i < ref.rgb.size(); ++i) {
    const double d = double(img.rgb[i]) - ref.rgb[i];
    sum += d * d / (double(ref.rgb[i]) * ref.rgb[i] + 1e-2);
  }
  return sum / double(ref.rgb.size());
}

// The best ratio any allocation can reach under the per-sample variance model: for relMSE =
// mean(s_i^2 / n_i), Neyman allocation (n_i proportional to s_i) needs (mean s)^2 / mean(s^2) of
// the samples uniform sampling needs. s_i from a uniform render's own variance estimate.
double neyman_bound(const penumbra::RenderResult& r, int spp) {
  double sum = 0.0, sum_sq = 0.0;
  const size_t pixels = r.image.rgb.size() / 3;
  for (size_t p = 0; p < pixels; ++p) {
    double s2 = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double m = r.image.rgb[3 * p + c];
      s2 += r.variance.rgb[3 * p + c] * spp / (m * m + 1e-2) / 3.0;
    }
    sum += std::sqrt(s2);
    sum_sq += s2;
  }
  return sum_sq > 0 ? (sum / pixels) * (sum / pixels) / (sum_sq / pixels) : 1.0;
}

struct Point {
  int spp;
  float threshold;
  double spp_mean = 0, rays = 0, seconds = 0, relmse = 0, bound = 0;  // means over seeds
};

// Cost uniform sampling needs for `relmse`, interpolated log-log between the ladder's points
// (extrapolated from the nearest segment beyond its ends; *extrapolated is set then).
double uniform_cost(const std::vector<Point>& ladder, double relmse, bool by_rays, bool* extrapolated) {
  auto cost = [&](const Point& p) { return by_rays ? p.rays : p.seconds; };
  size_t k = 0;
  while (k + 2 < ladder.size() && ladder[k + 1].relmse > relmse) ++k;
  const Point &a = ladder[k], &b = ladder[k + 1];
  *extrapolated = relmse > a.relmse || relmse < b.relmse;
  const double f = std::log(relmse / a.relmse) / std::log(b.relmse / a.relmse);
  return std::exp(std::log(cost(a)) + f * std::log(cost(b) / cost(a)));
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 4;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc) seeds = std::atoi(argv[++i]);
    else scenes.push_back(argv[i]);
  }
  if (scenes.empty()) {
    for (const auto& e : std::filesystem::directory_iterator("tests/accuracy/scenes"))
      if (e.path().extension() == ".json") scenes.push_back(e.path().stem().string());
    std::sort(scenes.begin(), scenes.end());
  }
  const int threads = 2;
  std::printf("scene,method,spp,threshold,seeds,spp_mean,rays,seconds,relmse\n");
  std::fprintf(stderr,
               "| scene | threshold | mean spp | relMSE | rays | uniform needs | rays ratio | "
               "Neyman bound | seconds | uniform needs | time ratio |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : scenes) {
    const auto loaded = penumbra::api::load_scene_file("tests/accuracy/scenes/" + name + ".json");
    if (!loaded.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), loaded.errors[0].to_string().c_str());
      return 1;
    }
    const penumbra::Image ref = penumbra::read_image_file("tests/accuracy/references/" + name + ".exr");
    const auto scene = penumbra::Scene::build(loaded.request->scene);
    auto run = [&](int spp, float threshold) {
      Point p{spp, threshold};
      for (int seed = 0; seed < seeds; ++seed) {
        penumbra::RenderSettings s = loaded.request->settings;
        s.threads = threads;
        s.spp = spp;
        s.seed = uint64_t(seed) + 1;
        s.noise_threshold = threshold;
        const auto t0 = std::chrono::steady_clock::now();
        const penumbra::RenderResult r = penumbra::render(*scene, s);
        p.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / seeds;
        p.spp_mean += r.stats.spp_mean / seeds;
        p.rays += double(r.stats.rays) / seeds;
        p.relmse += rel_mse(r.image, ref) / seeds;
        p.bound += neyman_bound(r, spp) / seeds;
      }
      std::printf("%s,%s,%d,%g,%d,%.2f,%.0f,%.4f,%.6g\n", name.c_str(),
                  threshold > 0 ? "adaptive" : "uniform", spp, double(threshold), seeds, p.spp_mean,
                  p.rays, p.seconds, p.relmse);
      std::fflush(stdout);
      return p;
    };
    std::vector<Point> ladder;
    for (int spp : {16, 32, 64, 128, 256, 512, 1024}) ladder.push_back(run(spp, 0.f));
    const double bound = ladder[4].bound;  // from the 256 spp renders
    for (float t : {0.1f, 0.05f, 0.03f}) {
      const Point a = run(1024, t);
      bool ex_rays = false, ex_secs = false;
      const double rays = uniform_cost(ladder, a.relmse, true, &ex_rays);
      const double secs = uniform_cost(ladder, a.relmse, false, &ex_secs);
      std::fprintf(stderr,
                   "| %s | %g | %.0f | %.2g | %.2fM | %.2fM%s | **%.2f** | %.2f | %.2f s | %.2f s%s | %.2f |\n",
                   name.c_str(), double(t), a.spp_mean, a.relmse, a.rays / 1e6, rays / 1e6,
                   ex_rays ? " (extrapolated)" : "", a.rays / rays, bound, a.seconds, secs,
                   ex_secs ? " (extrapolated)" : "", a.seconds / secs);
    }
  }
  return 0;
}
