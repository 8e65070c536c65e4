// Loading a 1M-triangle mesh file: the PLY reader alone (binary and ASCII), the OBJ reader, and
// the whole scene load (read, transform, degenerate check, normals) the CLI does before
// rendering; Scene::build (Embree's BVH) for comparison. The files are generated on first use
// in the system temp folder: a wavy 708 x 708 grid of quads, written as 1,002,528 triangles with
// vertex normals and uvs. docs/mesh-files.md has the numbers.
//
//   build/bench/mesh_load_benchmark [--benchmark_filter=Ply]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/io/mesh_file.h"
#include "renderer/scene/scene.h"

namespace {

namespace fs = std::filesystem;
using penumbra::vec2;
using penumbra::vec3;

constexpr int kGrid = 708;  // quads per side: 2 * 708^2 = 1,002,528 triangles

fs::path bench_dir() { return fs::temp_directory_path() / "penumbra_mesh_load_benchmark"; }

struct Grid {
  std::vector<vec3> positions, normals;
  std::vector<vec2> uvs;
  std::vector<uint32_t> triangles;
};

Grid wavy_grid() {
  Grid g;
  const int n = kGrid + 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float u = float(i) / kGrid, v = float(j) / kGrid;
      const float x = 2 * u - 1, z = 2 * v - 1;
      const float y = 0.05f * std::sin(12 * x) * std::cos(9 * z);
      const vec3 dx(1, 0.6f * std::cos(12 * x) * std::cos(9 * z), 0);
      const vec3 dz(0, -0.45f * std::sin(12 * x) * std::sin(9 * z), 1);
      g.positions.emplace_back(x, y, z);
      g.normals.push_back(glm::normalize(glm::cross(dz, dx)));
      g.uvs.emplace_back(u, v);
    }
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i) {
      const uint32_t a = uint32_t(j * n + i), b = a + 1, c = a + uint32_t(n), d = c + 1;
      g.triangles.insert(g.triangles.end(), {a, c, d, a, d, b});
    }
  return g;
}

void write_ply(const Grid& g, const fs::path& path, bool ascii) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat " << (ascii ? "ascii" : "binary_little_endian") << " 1.0\n"
      << "element vertex " << g.positions.size() << "\n";
  for (const char* p : {"x", "y", "z", "nx", "ny", "nz", "u", "v"})
    out << "property float " << p << "\n";
  out << "element face " << g.triangles.size() / 3
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (size_t i = 0; i < g.positions.size(); ++i) {
    const float v[8] = {g.positions[i].x, g.positions[i].y, g.positions[i].z, g.normals[i].x,
                        g.normals[i].y,   g.normals[i].z,   g.uvs[i].x,       g.uvs[i].y};
    if (ascii) {
      char line[160];
      std::snprintf(line, sizeof line, "%.7g %.7g %.7g %.7g %.7g %.7g %.7g %.7g\n", v[0], v[1],
                    v[2], v[3], v[4], v[5], v[6], v[7]);
      out << line;
    } else {
      out.write(reinterpret_cast<const char*>(v), sizeof v);
    }
  }
  for (size_t t = 0; t < g.triangles.size(); t += 3) {
    if (ascii) {
      out << "3 " << g.triangles[t] << " " << g.triangles[t + 1] << " " << g.triangles[t + 2]
          << "\n";
    } else {
      char face[13];
      face[0] = 3;
      std::memcpy(face + 1, &g.triangles[t], 12);
      out.write(face, sizeof face);
    }
  }
}

void write_obj(const Grid& g, const fs::path& path) {
  std::ofstream out(path);
  char line[128];
  for (const vec3& p : g.positions) {
    std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", p.x, p.y, p.z);
    out << line;
  }
  for (const vec3& n : g.normals) {
    std::snprintf(line, sizeof line, "vn %.7g %.7g %.7g\n", n.x, n.y, n.z);
    out << line;
  }
  for (const vec2& uv : g.uvs) {
    std::snprintf(line, sizeof line, "vt %.7g %.7g\n", uv.x, uv.y);
    out << line;
  }
  for (size_t t = 0; t < g.triangles.size(); t += 3) {
    out << "f";
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = g.triangles[t + k] + 1;
      out << " " << i << "/" << i << "/" << i;
    }
    out << "\n";
  }
}

// The files, written once per machine (regenerated if missing).
const fs::path& mesh_files() {
  static const fs::path dir = [] {
    const fs::path d = bench_dir();
    if (!fs::exists(d / "scene.json")) {
      fs::create_directories(d);
      const Grid g = wavy_grid();
      write_ply(g, d / "grid_binary.ply", false);
      write_ply(g, d / "grid_ascii.ply", true);
      write_obj(g, d / "grid.obj");
      std::ofstream(d / "scene.json") << R"({"version": 1,
        "camera": {"position": [0, 2, 3], "look_at": [0, 0, 0]},
        "materials": {"m": {"type": "diffuse"}},
        "environment": {"radiance": [1, 1, 1]},
        "objects": [{"type": "mesh", "file": "grid_binary.ply", "material": "m",
                     "transform": {"rotate": {"axis": [0, 1, 0], "degrees": 30}}}]})";
    }
    return d;
  }();
  return dir;
}

void read_file(benchmark::State& state, const char* name) {
  const fs::path path = mesh_files() / name;
  int64_t triangles = 0;
  for (auto _ : state) {
    const penumbra::MeshFile file = penumbra::read_mesh_file(path, name);
    triangles = int64_t(file.mesh.indices.size() / 3);
    benchmark::DoNotOptimize(file.mesh.positions.data());
  }
  state.counters["triangles"] = double(triangles);
  state.counters["MB"] = double(fs::file_size(path)) / 1e6;
}

void BM_ReadPlyBinary(benchmark::State& state) { read_file(state, "grid_binary.ply"); }
void BM_ReadPlyAscii(benchmark::State& state) { read_file(state, "grid_ascii.ply"); }
void BM_ReadObj(benchmark::State& state) { read_file(state, "grid.obj"); }

// What `penumbra render` does before Scene::build: the whole scene load.
void BM_LoadSceneWithPly(benchmark::State& state) {
  const std::string scene = (mesh_files() / "scene.json").string();
  for (auto _ : state) {
    const penumbra::api::LoadResult r = penumbra::api::load_scene_file(scene);
    if (!r.ok()) state.SkipWithError(r.errors.front().to_string().c_str());
    benchmark::DoNotOptimize(r.request);
  }
}

void BM_SceneBuild(benchmark::State& state) {
  const penumbra::api::LoadResult r =
      penumbra::api::load_scene_file((mesh_files() / "scene.json").string());
  if (!r.ok()) {
    state.SkipWithError(r.errors.front().to_string().c_str());
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(penumbra::Scene::build(r.request->scene));
}

BENCHMARK(BM_ReadPlyBinary)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_ReadPlyAscii)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_ReadObj)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_LoadSceneWithPly)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_SceneBuild)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
