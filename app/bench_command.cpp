// penumbra bench: the renderer's rays/s against Embree alone on the same scene, in one run.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "app/commands.h"
#include "app/option_parsing.h"
#include "renderer/render/embree_baseline.h"
#include "renderer/render/embree_ray_forms.h"
#include "renderer/render/render.h"

namespace penumbra::app {
namespace {

const char* kUsage =
    "usage: penumbra bench [SCENE.json] [options]\n"
    "\n"
    "Renders the scene with the path integrator and traces the same kind of rays with Embree\n"
    "alone (camera, shadow and bounce rays, no shading), alternating the two REPEAT times, and\n"
    "prints both rays/s and their ratio (median of the runs). Then the same scene's camera rays,\n"
    "their shadow rays and their bounce rays, pre-generated, traced by Embree alone one by one,\n"
    "in 16-wide packets and as streams (best of REPEAT), as a table with the renderer's median\n"
    "rays/s against each. Default scene: scenes/cornell_box.json.\n"
    "  --repeat N      alternating runs of each (default 5)\n"
    "  --spp, --width, --height, --threads, --max-depth, --seed ...   as for render\n";

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// One row per kind of ray, one column pair per Embree calling form: Mrays/s and the renderer's
// median rays/s as a fraction of it.
void print_ray_forms(const std::vector<RayFormResult>& results, double renderer_mrays) {
  std::printf("\nEmbree alone on pre-generated rays (best of the runs; ratio = renderer / this):\n");
  std::printf("| rays | count | single (rtc*1) Mrays/s | ratio | packet (rtc*16) Mrays/s | ratio | stream (rtc*1M) Mrays/s | ratio |\n");
  std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  for (size_t i = 0; i + 2 < results.size(); i += 3) {
    std::printf("| %s | %llu", ray_kind_name(results[i].kind), (unsigned long long)results[i].rays);
    for (size_t j = i; j < i + 3; ++j) {
      const double m = results[j].mrays_per_second();
      std::printf(" | %.2f | %.3f", m, m > 0 ? renderer_mrays / m : 0.0);
    }
    std::printf(" |\n");
    // The forms must agree on what they hit; a mismatch would make the rates incomparable.
    if (results[i].hits != results[i + 1].hits || results[i].hits != results[i + 2].hits)
      std::printf("warning: %s rays: hits differ between forms (%llu, %llu, %llu)\n", ray_kind_name(results[i].kind),
                  (unsigned long long)results[i].hits, (unsigned long long)results[i + 1].hits,
                  (unsigned long long)results[i + 2].hits);
  }
}

}  // namespace

int run_bench(int argc, char** argv) {
  std::string scene_path = "scenes/cornell_box.json";
  long long repeat = 5;
  std::vector<api::RenderOverride> overrides;
  OptionParser p(argc, argv);
  bool scene_given = false;
  while (p.next()) {
    if (p.is("-h") || p.is("--help")) {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (p.is("--repeat")) {
      if (!p.int_value(1, 1000, &repeat)) return p.fail(kUsage);
    } else if (parse_render_override(p, overrides)) {
      if (p.failed()) return p.fail(kUsage);
    } else if (p.positional() && !scene_given) {
      scene_path = p.arg();
      scene_given = true;
    } else {
      return p.fail(kUsage, "unexpected argument " + std::string(p.arg()));
    }
  }
  api::LoadResult loaded = api::load_scene_file(scene_path, {}, overrides);
  if (!loaded.ok()) {
    for (const auto& e : loaded.errors) std::fprintf(stderr, "%s: %s\n", scene_path.c_str(), e.to_string().c_str());
    return 1;
  }
  RenderSettings settings = loaded.request->settings;
  // The path integrator is what bench measures, unless the command line names another.
  if (std::none_of(overrides.begin(), overrides.end(),
                   [](const api::RenderOverride& o) { return o.flag == "--integrator"; }))
    settings.integrator = IntegratorKind::kPath;
  const auto scene = Scene::build(loaded.request->scene);
  scene->prepare_sampling(settings.integrator);

  std::vector<double> renderer_mrays, embree_mrays, ratios;
  for (long long i = 0; i < repeat; ++i) {
    const RenderResult r = render(*scene, settings);
    const BaselineResult b = trace_embree_baseline(*scene, settings);
    renderer_mrays.push_back(r.stats.mrays_per_second());
    embree_mrays.push_back(b.mrays_per_second());
    ratios.push_back(r.stats.mrays_per_second() / b.mrays_per_second());
    std::printf("run %lld: renderer %.2f Mrays/s (%.3f s, %.2f rays/sample)  embree-only %.2f Mrays/s (%.3f s)  ratio %.3f\n",
                i + 1, renderer_mrays.back(), r.stats.seconds,
                double(r.stats.rays) / double(std::max<uint64_t>(1, r.stats.camera_samples)),
                embree_mrays.back(), b.seconds, ratios.back());
  }
  std::printf("scene %s, %dx%d, %d spp, max_depth %d, threads %s\n", scene_path.c_str(), settings.width,
              settings.height, settings.spp, settings.max_depth,
              settings.threads > 0 ? std::to_string(settings.threads).c_str() : "all");
  std::printf("median: renderer %.2f Mrays/s, embree-only %.2f Mrays/s, ratio %.3f\n",
              median(renderer_mrays), median(embree_mrays), median(ratios));
  print_ray_forms(trace_embree_ray_forms(*scene, settings, int(repeat)), median(renderer_mrays));
  return 0;
}

}  // namespace penumbra::app
