// What textures cost: the same scene with constant parameters, and with an image texture on
// every material (issue 10 asks for at least 70% of the constant scene's rays/s).
//   build/bench/texture_cost_benchmark --benchmark_repetitions=5
//     --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
// As feature_cost_benchmark: a 64x64, 16 spp, depth-6 Cornell-like scene loaded through the
// public loader, rendered on ONE thread (CPU time is the render's cost), variants interleaved.
//  * constant: diffuse walls, a plastic floor, a rough conductor and a plastic sphere.
//  * textured: every colour a 512 x 512 sRGB texture (bilinear, repeat), the conductor's
//    roughness a 256 x 256 grey texture: every hit looks up one or two textures.
//  * textured_nearest: the same with nearest lookups.
//  * normal_mapped: textured, plus a 256 x 256 normal map on every material (tangent frame,
//    a third lookup and the perturbed-frame BSDF per hit).
// Mrays/s is rays per CPU second; the textures are written to a temporary folder first.
#include <OpenImageIO/imageio.h>
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"

namespace {

namespace fs = std::filesystem;

// Smooth-ish deterministic values in [0, 1] (sums of sines), so bilinear lookups see variety.
float pattern(int x, int y, int c) {
  return 0.5f + 0.25f * std::sin(0.07f * float(x) + 1.3f * float(c)) +
         0.2f * std::sin(0.11f * float(y) - 0.7f * float(c)) * std::cos(0.05f * float(x + y));
}

void write_image(const fs::path& path, int size, int channels, bool normal = false) {
  std::vector<unsigned char> px(size_t(size) * size * channels);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < channels; ++c) {
        float v = pattern(x, y, c);
        if (normal) v = c == 2 ? 0.9f : 0.5f + 0.3f * (v - 0.5f);  // mild tilts
        px[(size_t(y) * size + x) * channels + c] =
            (unsigned char)std::lround(std::clamp(v, 0.f, 1.f) * 255.f);
      }
  auto out = OIIO::ImageOutput::create(path.string());
  out->open(path.string(), OIIO::ImageSpec(size, size, channels, OIIO::TypeDesc::UINT8));
  out->write_image(OIIO::TypeDesc::UINT8, px.data());
  out->close();
}

const fs::path& texture_folder() {
  static const fs::path folder = [] {
    const fs::path f = fs::temp_directory_path() / "penumbra_texture_cost_benchmark";
    fs::create_directories(f);
    for (const char* name : {"white", "red", "green", "floor", "ball"})
      write_image(f / (std::string(name) + ".png"), 512, 3);
    write_image(f / "rough.png", 256, 1);
    write_image(f / "normal.png", 256, 3, true);
    return f;
  }();
  return folder;
}

struct Variant {
  bool textured = false;
  const char* filter = "bilinear";
  bool normal_maps = false;
};

std::string scene_json(const Variant& v) {
  auto color = [&](const char* name, const char* constant) {
    return v.textured
               ? std::string(R"({"texture": ")") + name + R"(.png", "filter": ")" + v.filter + "\"}"
               : std::string(constant);
  };
  const std::string normal = v.normal_maps ? R"(, "normal_map": "normal.png")" : "";
  const std::string roughness =
      v.textured
          ? std::string(R"({"texture": "rough.png", "scale": 0.6, "filter": ")") + v.filter + "\"}"
          : "0.35";
  return R"({"version": 1,
    "render": {"width": 64, "height": 64, "spp": 16, "max_depth": 6},
    "camera": {"position": [0, 1, 3.9], "look_at": [0, 1, 0], "fov": 40},
    "materials": {
      "white": {"type": "diffuse", "color": )" +
         color("white", "[0.73, 0.73, 0.73]") + normal + R"(},
      "red": {"type": "diffuse", "color": )" +
         color("red", "[0.63, 0.065, 0.05]") + normal + R"(},
      "green": {"type": "diffuse", "color": )" +
         color("green", "[0.14, 0.45, 0.091]") + normal + R"(},
      "floor": {"type": "plastic", "color": )" +
         color("floor", "[0.6, 0.55, 0.5]") + R"(, "roughness": 0.3)" + normal + R"(},
      "metal": {"type": "conductor", "color": [0.9, 0.8, 0.6], "roughness": )" +
         roughness + normal + R"(},
      "ball": {"type": "plastic", "color": )" +
         color("ball", "[0.2, 0.3, 0.7]") + normal + R"(}
    },
    "objects": [
      {"type": "quad", "origin": [-1, 0, 1], "u": [2, 0, 0], "v": [0, 0, -2], "material": "floor"},
      {"type": "quad", "origin": [-1, 0, -1], "u": [2, 0, 0], "v": [0, 2, 0], "material": "white"},
      {"type": "quad", "origin": [-1, 2, -1], "u": [2, 0, 0], "v": [0, 0, 2], "material": "white"},
      {"type": "quad", "origin": [-1, 0, 1], "u": [0, 0, -2], "v": [0, 2, 0], "material": "red"},
      {"type": "quad", "origin": [1, 0, -1], "u": [0, 0, 2], "v": [0, 2, 0], "material": "green"},
      {"type": "quad", "origin": [-0.25, 1.98, -0.25], "u": [0.5, 0, 0], "v": [0, 0, 0.5], "material": "white", "emission": [17, 12, 4]},
      {"type": "sphere", "center": [-0.4, 0.35, -0.2], "radius": 0.35, "material": "metal"},
      {"type": "sphere", "center": [0.45, 0.3, 0.3], "radius": 0.3, "material": "ball"}
    ]})";
}

void render_variant(benchmark::State& state, const std::string& json) {
  penumbra::api::AssetFolder assets;
  assets.root = texture_folder();
  const penumbra::api::LoadResult loaded = penumbra::api::load_scene(json, {}, {}, assets);
  if (!loaded.ok()) {
    state.SkipWithError(("scene does not load: " + loaded.errors[0].to_string()).c_str());
    return;
  }
  const auto scene = penumbra::Scene::build(loaded.request->scene);
  penumbra::RenderSettings s = loaded.request->settings;
  s.threads = 1;
  uint64_t rays = 0;
  for (auto _ : state) {
    const penumbra::RenderResult r = penumbra::render(*scene, s);
    rays += r.stats.rays;
    benchmark::DoNotOptimize(r.image.rgb.data());
  }
  state.counters["Mrays/s"] = benchmark::Counter(double(rays) * 1e-6, benchmark::Counter::kIsRate);
}

const bool kRegistered = [] {
  std::map<std::string, Variant> variants;
  variants["constant"] = {};
  variants["textured"] = {true};
  variants["textured_nearest"] = {true, "nearest"};
  variants["normal_mapped"] = {true, "bilinear", true};
  for (const auto& [name, v] : variants)
    benchmark::RegisterBenchmark(("texture/" + name).c_str(), render_variant, scene_json(v))
        ->Unit(benchmark::kMillisecond)
        ->MinTime(1.0);
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
