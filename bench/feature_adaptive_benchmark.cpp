// Adaptive sampling (render.noise_threshold) against uniform sampling: render time and relMSE
// against the Mitsuba 3 reference (8192 spp) of accuracy scenes. Prints CSV:
//   scene,method,spp,threshold,spp_mean,rays,seconds,relmse
//   build/bench/feature_adaptive_benchmark [SCENE...] > docs/adaptive_sampling.csv
// (run from the repository root; default scenes: cornell all_lights glass_rough).
// relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 1e-2), the usual
// relative MSE with a small floor so black pixels do not dominate.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/image_io.h"
#include "renderer/render.h"
#include "renderer/scene.h"

namespace {

double rel_mse(const penumbra::Image& img, const penumbra::Image& ref) {
  double sum = 0.0;
  for (size_t i = 0; i < ref.rgb.size(); ++i) {
    const double d = double(img.rgb[i]) - ref.rgb[i];
    sum += d * d / (double(ref.rgb[i]) * ref.rgb[i] + 1e-2);
  }
  return sum / double(ref.rgb.size());
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) scenes.push_back(argv[i]);
  if (scenes.empty()) scenes = {"cornell", "all_lights", "glass_rough"};
  const int threads = 2;
  std::printf("scene,method,spp,threshold,spp_mean,rays,seconds,relmse\n");
  for (const std::string& name : scenes) {
    const auto loaded = penumbra::api::load_scene_file("tests/accuracy/scenes/" + name + ".json");
    if (!loaded.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), loaded.errors[0].to_string().c_str());
      return 1;
    }
    const penumbra::Image ref = penumbra::read_image_file("tests/accuracy/references/" + name + ".exr");
    const auto scene = penumbra::Scene::build(loaded.request->scene);
    auto run = [&](const char* method, int spp, float threshold) {
      penumbra::RenderSettings s = loaded.request->settings;
      s.threads = threads;
      s.spp = spp;
      s.noise_threshold = threshold;
      const auto t0 = std::chrono::steady_clock::now();
      const penumbra::RenderResult r = penumbra::render(*scene, s);
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("%s,%s,%d,%g,%.2f,%llu,%.4f,%.6g\n", name.c_str(), method, spp, double(threshold),
                  r.stats.spp_mean, (unsigned long long)r.stats.rays, secs, rel_mse(r.image, ref));
      std::fflush(stdout);
    };
    // Rays traced is the machine-independent cost; seconds are on the 2 threads.
    for (int spp : {32, 64, 128, 256, 512, 1024}) run("uniform", spp, 0.f);
    for (int spp : {128, 256, 512, 1024})
      for (float t : {0.1f, 0.05f, 0.03f}) run("adaptive", spp, t);
  }
  return 0;
}
