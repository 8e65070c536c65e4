// Importance sampling of an environment map against sampling it uniformly over the sphere, at
// equal render time, on a sun-and-sky scene: how much lower the relMSE is.
//
//   build/bench/environment_sampling_benchmark [--seeds N] [--reference-spp N] [SCENE [REFERENCE]]
//     > docs/environment_sampling.csv 2> docs/environment_sampling.md
//
// (run from the repository root; default: scenes/sun_and_sky.json, 4 seeds, 2 threads). Both
// strategies are combined with BSDF sampling by MIS in the path integrator; only the density with
// which next-event estimation picks directions on the map differs
// (EnvironmentMapDesc::uniform_sampling, which only benchmarks set). Each renders an spp ladder
// (4..128), averaged over the seeds; one CSV row per render. The markdown table on stderr gives,
// for each importance-sampled render, the relMSE uniform sampling reaches in the same time
// (log-log interpolation of its ladder) and the ratio.
//
// The reference is REFERENCE (an EXR, with its standard error in <name>.stderr.exr beside it, as
// tools/make_references.py writes) or, without one, an importance-sampled render of
// --reference-spp samples (default 4096; its own variance estimate gives the standard error).
// relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 1e-2), as
// feature_adaptive_benchmark; "floor" is the part the reference's own noise contributes (mean of
// stderr^2 / (ref^2 + 1e-2)), which both strategies pay alike.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

struct Point {
  int spp = 0;
  double seconds = 0, rays = 0, relmse = 0;  // means over seeds
};

// relMSE of `ladder` at `seconds`, interpolated log-log (extrapolated from the end segments).
double relmse_at(const std::vector<Point>& ladder, double seconds, bool* extrapolated) {
  size_t k = 0;
  while (k + 2 < ladder.size() && ladder[k + 1].seconds < seconds) ++k;
  const Point &a = ladder[k], &b = ladder[k + 1];
  *extrapolated = seconds < a.seconds || seconds > b.seconds;
  const double f = std::log(seconds / a.seconds) / std::log(b.seconds / a.seconds);
  return std::exp(std::log(a.relmse) + f * std::log(b.relmse / a.relmse));
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 4, reference_spp = 4096;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc) seeds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--reference-spp") && i + 1 < argc) reference_spp = std::atoi(argv[++i]);
    else positional.push_back(argv[i]);
  }
  if (positional.size() > 2 || seeds < 1 || reference_spp < 1) {
    std::fprintf(stderr, "usage: %s [--seeds N] [--reference-spp N] [SCENE [REFERENCE]]\n", argv[0]);
    return 2;
  }
  const std::string scene_path = positional.empty() ? "scenes/sun_and_sky.json" : positional[0];
  auto loaded = penumbra::api::load_scene_file(scene_path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "%s: %s\n", scene_path.c_str(), loaded.errors[0].to_string().c_str());
    return 1;
  }
  if (!loaded.request->scene.environment_map) {
    std::fprintf(stderr, "%s: the scene has no environment map\n", scene_path.c_str());
    return 1;
  }
  penumbra::Image ref, ref_se;
  if (positional.size() == 2) {
    ref = penumbra::read_image_file(positional[1]);
    std::string se_path = positional[1];
    se_path.replace(se_path.rfind(".exr"), 4, ".stderr.exr");
    ref_se = penumbra::read_image_file(se_path);
  } else {
    const auto scene = penumbra::Scene::build(loaded.request->scene);
    penumbra::RenderSettings s = loaded.request->settings;
    s.threads = 2;
    s.spp = reference_spp;
    s.seed = 1000;
    penumbra::RenderResult r = penumbra::render(*scene, s);
    ref = std::move(r.image);
    ref_se = std::move(r.variance);
    for (float& v : ref_se.rgb) v = std::sqrt(v);
  }
  double floor = 0.0;
  for (size_t i = 0; i < ref.rgb.size(); ++i)
    floor += double(ref_se.rgb[i]) * ref_se.rgb[i] / (double(ref.rgb[i]) * ref.rgb[i] + 1e-2);
  floor /= double(ref.rgb.size());

  std::printf("method,spp,seeds,seconds,rays,relmse\n");
  auto ladder = [&](bool uniform) {
    penumbra::SceneInput input = loaded.request->scene;
    input.environment_map->uniform_sampling = uniform;
    const auto scene = penumbra::Scene::build(input);
    std::vector<Point> points;
    for (int spp : {4, 8, 16, 32, 64, 128}) {
      Point p;
      p.spp = spp;
      for (int seed = 0; seed < seeds; ++seed) {
        penumbra::RenderSettings s = loaded.request->settings;
        s.threads = 2;
        s.spp = spp;
        s.seed = uint64_t(seed) + 1;
        const auto t0 = std::chrono::steady_clock::now();
        const penumbra::RenderResult r = penumbra::render(*scene, s);
        p.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / seeds;
        p.rays += double(r.stats.rays) / seeds;
        p.relmse += rel_mse(r.image, ref) / seeds;
      }
      std::printf("%s,%d,%d,%.4f,%.0f,%.6g\n", uniform ? "uniform" : "importance", spp, seeds,
                  p.seconds, p.rays, p.relmse);
      std::fflush(stdout);
      points.push_back(p);
    }
    return points;
  };
  const std::vector<Point> importance = ladder(false);
  const std::vector<Point> uniform = ladder(true);

  std::fprintf(stderr,
               "Scene `%s`, %d seeds, reference %s; relMSE floor from the reference's own noise: "
               "%.2g.\n\n"
               "| spp (importance) | seconds | relMSE importance | relMSE uniform, same time | "
               "ratio | ratio above the floor |\n|---|---|---|---|---|---|\n",
               scene_path.c_str(), seeds,
               positional.size() == 2 ? positional[1].c_str()
                                      : (std::to_string(reference_spp) + " spp, importance sampled").c_str(),
               floor);
  for (const Point& p : importance) {
    bool extrapolated = false;
    const double u = relmse_at(uniform, p.seconds, &extrapolated);
    std::fprintf(stderr, "| %d | %.3f | %.3g | %.3g%s | **%.1f** | %.1f |\n", p.spp, p.seconds,
                 p.relmse, u, extrapolated ? " (extrapolated)" : "", u / p.relmse,
                 (u - floor) / std::max(p.relmse - floor, 1e-12));
  }
  return 0;
}
