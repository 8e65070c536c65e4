// What each scene feature costs, and that an absent feature costs nothing.
//   build/bench/feature_cost_benchmark --benchmark_repetitions=5
//     --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
// Every benchmark renders one variant of the same small scene (64x64, 16 spp, path, depth 6)
// built once through the public loader (api::load_scene on JSON text), on ONE thread, which is
// the calling thread: its CPU time (the "CPU" column) is the render's cost and is far less
// disturbed by other load on a shared machine than wall time. Random interleaving runs the
// variants alternately, so drifts affect all alike.
//  * base vs zero_fields: the same scene, once without motion/lens fields and once with
//    velocity [0,0,0], acceleration [0,0,0], aperture_radius 0 and a shutter: must be within 3%.
//  * one feature added at a time: motion, lens, transmission, absorption, point light,
//    directional light, environment; and the geometry as meshes only vs spheres only.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>

#include "api/scene_loader.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"

namespace {

struct Variant {
  std::string camera_extra;   // appended inside "camera"
  std::string sphere_extra;   // appended to every sphere object
  std::string quad_extra;     // appended to every quad object
  std::string glass = R"({"type": "diffuse", "color": [0.5, 0.5, 0.5]})";
  std::string top_extra;      // top-level members (environment, lights)
  bool spheres_as_meshes = false;
  bool meshes_as_spheres = false;
};

std::string icosahedron_mesh(double cx, double cy, double cz, double r, const std::string& mat) {
  // A coarse closed mesh standing in for a sphere (12 vertices, 20 faces).
  const double t = (1.0 + std::sqrt(5.0)) / 2.0, n = r / std::sqrt(1 + t * t);
  const double v[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::string pos;
  for (int i = 0; i < 12; ++i)
    pos += (i ? "," : "") + std::to_string(cx + v[i][0] * n) + "," + std::to_string(cy + v[i][1] * n) + "," +
           std::to_string(cz + v[i][2] * n);
  return R"({"type": "mesh", "material": ")" + mat + R"(", "positions": [)" + pos +
         R"(], "indices": [0,11,5, 0,5,1, 0,1,7, 0,7,10, 0,10,11, 1,5,9, 5,11,4, 11,10,2, 10,7,6, 7,1,8,
         3,9,4, 3,4,2, 3,2,6, 3,6,8, 3,8,9, 4,9,5, 2,4,11, 6,2,10, 8,6,7, 9,8,1]})";
}

std::string scene_json(const Variant& v) {
  auto sphere = [&](const char* c, const char* r, const char* m) {
    return std::string(R"({"type": "sphere", "center": )") + c + R"(, "radius": )" + r + R"(, "material": ")" + m +
           "\"" + v.sphere_extra + "}";
  };
  auto quad = [&](const char* o, const char* u, const char* w, const char* m, const char* extra = "") {
    return std::string(R"({"type": "quad", "origin": )") + o + R"(, "u": )" + u + R"(, "v": )" + w +
           R"(, "material": ")" + m + "\"" + extra + v.quad_extra + "}";
  };
  std::string objects;
  if (v.meshes_as_spheres) {
    // Walls as huge spheres far away: geometry without any triangle except the light.
    objects += sphere("[0, -1000, 0]", "1000", "white") + "," + sphere("[0, 0, -1001]", "1000", "white") + ",";
  } else {
    objects += quad("[-1, 0, 1]", "[2, 0, 0]", "[0, 0, -2]", "white") + ",";
    objects += quad("[-1, 0, -1]", "[2, 0, 0]", "[0, 2, 0]", "white") + ",";
    objects += quad("[-1, 0, 1]", "[0, 0, -2]", "[0, 2, 0]", "red") + ",";
    objects += quad("[1, 0, -1]", "[0, 0, 2]", "[0, 2, 0]", "green") + ",";
  }
  objects += quad("[-0.25, 1.98, -0.25]", "[0.5, 0, 0]", "[0, 0, 0.5]", "white", R"(, "emission": [17, 12, 4])");
  if (v.spheres_as_meshes) {
    objects += "," + icosahedron_mesh(-0.4, 0.35, -0.2, 0.35, "glass") + "," + icosahedron_mesh(0.45, 0.3, 0.3, 0.3, "white");
  } else {
    objects += "," + sphere("[-0.4, 0.35, -0.2]", "0.35", "glass") + "," + sphere("[0.45, 0.3, 0.3]", "0.3", "white");
  }
  return R"({"version": 1,
    "render": {"width": 64, "height": 64, "spp": 16, "max_depth": 6},
    "camera": {"position": [0, 1, 3.9], "look_at": [0, 1, 0], "fov": 40)" + v.camera_extra + R"(},
    "materials": {
      "white": {"type": "diffuse", "color": [0.73, 0.73, 0.73]},
      "red": {"type": "diffuse", "color": [0.63, 0.065, 0.05]},
      "green": {"type": "diffuse", "color": [0.14, 0.45, 0.091]},
      "glass": )" + v.glass + R"(},
    "objects": [)" + objects + "]" + v.top_extra + "}";
}

std::map<std::string, Variant> variants() {
  std::map<std::string, Variant> m;
  m["base"] = {};
  Variant zero;
  zero.camera_extra = R"(, "aperture_radius": 0, "focus_distance": 3.9, "shutter": [0, 1])";
  zero.sphere_extra = R"(, "velocity": [0, 0, 0], "acceleration": [0, 0, 0])";
  zero.quad_extra = R"(, "velocity": [0, 0, 0])";
  m["zero_fields"] = zero;
  Variant motion;
  motion.camera_extra = R"(, "shutter": [0, 1])";
  motion.sphere_extra = R"(, "velocity": [0.2, 0, 0], "acceleration": [0, -0.2, 0])";
  m["motion"] = motion;
  Variant lens;
  lens.camera_extra = R"(, "aperture_radius": 0.05, "focus_distance": 3.9)";
  m["lens"] = lens;
  Variant glass;
  glass.glass = R"({"type": "dielectric", "ior": 1.5})";
  m["transmission"] = glass;
  Variant absorb;
  absorb.glass = R"({"type": "dielectric", "ior": 1.5, "absorption": [0.5, 1, 2]})";
  m["absorption"] = absorb;
  Variant point;
  point.top_extra = R"(, "lights": [{"type": "point", "position": [0.3, 1.7, 0.5], "intensity": [2, 2, 2]}])";
  m["point_light"] = point;
  Variant dir;
  dir.top_extra = R"(, "lights": [{"type": "directional", "direction": [0.2, -1, -0.3], "irradiance": [1, 1, 1]}])";
  m["directional_light"] = dir;
  Variant env;
  env.top_extra = R"(, "environment": {"radiance": [0.2, 0.25, 0.3]})";
  m["environment"] = env;
  Variant meshes;
  meshes.spheres_as_meshes = true;
  m["meshes_only"] = meshes;
  Variant spheres;
  spheres.meshes_as_spheres = true;
  m["spheres_only"] = spheres;
  return m;
}

void render_variant(benchmark::State& state, const std::string& json) {
  const penumbra::api::LoadResult loaded = penumbra::api::load_scene(json);
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
  for (const auto& [name, v] : variants())
    benchmark::RegisterBenchmark(("feature/" + name).c_str(), render_variant, scene_json(v))
        ->Unit(benchmark::kMillisecond)
        ->MinTime(1.0);
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
