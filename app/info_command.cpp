// `penumbra info FILE...`: what a scene or an asset file contains and what rendering it costs.
// Each kind of file is one entry of kKinds (a predicate on the name and a printer), so a new
// asset kind (textures, environment maps) adds one printer and one line there.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "api/scene_loader.h"
#include "app/commands.h"
#include "app/load_report.h"
#include "app/option_parsing.h"
#include "api/gltf_scene.h"
#include "renderer/io/gltf_file.h"
#include "renderer/io/mesh_file.h"
#include "renderer/scene/memory_estimate.h"

namespace penumbra::app {

namespace {

// The environment line's kind: an image map (its size), a constant radiance, or black.
std::string environment_kind(const SceneInput& scene) {
  if (scene.environment_map)
    return "map " + std::to_string(scene.environment_map->width) + " x " +
           std::to_string(scene.environment_map->height);
  return is_black(scene.environment) ? "black" : "constant";
}

namespace fs = std::filesystem;

void print_help(std::FILE* out) {
  std::fprintf(out,
               "usage: penumbra info FILE [MORE ...]\n"
               "\n"
               "Prints what each file contains: for a scene (.json) or a glTF asset (.gltf,\n"
               ".glb, described as 'penumbra render' would render it) its objects, triangles,\n"
               "lights, the files it reads and an estimate of the memory a render needs; for a\n"
               "mesh file (.ply, .obj) its faces, triangles, vertices, attributes and bounds.\n"
               "Problems go to stderr as 'penumbra validate' prints them.\n"
               "\n"
               "exit status: 0 all files read, 1 some file unreadable or invalid, 2 usage error\n");
}

std::string byte_size(int64_t bytes) {
  char buf[32];
  if (bytes < 1024 * 1024)
    std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
  else if (bytes < int64_t(1) << 30)
    std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / (1 << 20));
  else
    std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / double(int64_t(1) << 30));
  return buf;
}

void print_memory(const MemoryEstimate& m, bool with_film) {
  std::printf(
      "  memory      about %s: scene input %s, renderer copies %s, Embree %s (+%s while "
      "building)%s%s\n",
      byte_size(m.total()).c_str(), byte_size(m.scene_input).c_str(), byte_size(m.shapes).c_str(),
      byte_size(m.embree).c_str(), byte_size(m.embree_build_peak).c_str(),
      m.textures > 0 ? (", textures " + byte_size(m.textures)).c_str() : "",
      with_film ? (", film " + byte_size(m.film)).c_str() : "");
}

struct Count {
  const char* one;
  const char* many;
  int64_t n;
};

// "3 quads, 1 sphere", leaving out the kinds with none.
std::string list_counts(const std::vector<Count>& counts) {
  std::string out;
  for (const Count& c : counts) {
    if (c.n == 0) continue;
    if (!out.empty()) out += ", ";
    out += std::to_string(c.n) + " " + (c.n == 1 ? c.one : c.many);
  }
  return out.empty() ? "none" : out;
}

// ---- scenes ----------------------------------------------------------------------------------

bool is_scene(const fs::path& path) { return path.extension() == ".json"; }
bool is_gltf(const fs::path& path) { return is_gltf_file_name(path.string()); }

int print_scene(const std::string& file) {
  const api::LoadResult result = api::load_scene_file(file);
  if (!report_load_problems(file, result)) return 1;
  const api::SceneRequest& request = *result.request;
  const SceneInput& scene = request.scene;
  const RenderSettings& settings = request.settings;

  int64_t spheres = 0, quads = 0, meshes = 0, emitting = 0, triangles = 0, vertices = 0;
  for (const ObjectDesc& object : scene.objects) {
    if (!is_black(object.emission)) ++emitting;
    if (std::holds_alternative<SphereDesc>(object.shape)) ++spheres;
    if (std::holds_alternative<QuadDesc>(object.shape)) ++quads;
    if (const auto* mesh = std::get_if<MeshDesc>(&object.shape)) {
      ++meshes;
      triangles += int64_t(mesh->indices.size() / 3);
      vertices += int64_t(mesh->positions.size());
    }
  }
  // Copies placed by instances objects, and the triangles they draw (not stored again).
  int64_t copies = 0, drawn = triangles;
  std::set<uint32_t> copied;
  for (const InstancesDesc& set : scene.instances) {
    copied.insert(set.object);
    copies += int64_t(set.transforms.size());
    if (const auto* mesh = std::get_if<MeshDesc>(&scene.objects[set.object].shape))
      drawn += int64_t(set.transforms.size()) * int64_t(mesh->indices.size() / 3);
  }
  int64_t points = 0, directionals = 0;
  for (const LightDesc& light : scene.lights)
    (std::holds_alternative<PointLightDesc>(light) ? points : directionals)++;

  std::printf("%s: %s %d x %d pixels, %d spp\n", file.c_str(),
              is_gltf(file) ? "glTF asset, rendered at" : "scene,", settings.width, settings.height,
              settings.spp);
  if (settings.window)
    std::printf("  window      [%d, %d, %d, %d): %d x %d pixels\n", settings.window->x0, settings.window->y0,
                settings.window->x1, settings.window->y1, settings.window->width(), settings.window->height());
  if (request.animation)
    std::printf("  animation   frames %lld to %lld (%lld), %g fps, shutter %g of a frame\n",
                static_cast<long long>(request.animation->first_frame),
                static_cast<long long>(request.animation->last_frame),
                static_cast<long long>(request.animation->frame_count()), request.animation->fps,
                request.animation->shutter);
  std::printf(
      "  objects     %zu: %s; %lld emitting\n", scene.objects.size() + scene.instances.size(),
      list_counts({{"sphere", "spheres", spheres},
                   {"quad", "quads", quads},
                   {"mesh", "meshes", meshes},
                   {"instances object", "instances objects", int64_t(scene.instances.size())}})
          .c_str(),
      static_cast<long long>(emitting));
  std::printf("  triangles   %lld\n", static_cast<long long>(triangles));
  if (!scene.instances.empty())
    std::printf("  instances   %lld %s of %zu %s, %lld triangles drawn in all\n",
                static_cast<long long>(copies), copies == 1 ? "copy" : "copies",
                copied.size(), copied.size() == 1 ? "mesh" : "meshes",
                static_cast<long long>(drawn));
  std::printf("  vertices    %lld\n", static_cast<long long>(vertices));
  std::printf("  lights      %s; environment %s\n",
              list_counts({{"point light", "point lights", points},
                           {"directional light", "directional lights", directionals}})
                  .c_str(),
              environment_kind(scene).c_str());
  std::printf("  materials   %zu\n", scene.materials.size());
  std::printf("  files       %zu\n", request.assets.size());
  for (const api::AssetUse& asset : request.assets)
    std::printf("    %s  %s: %s\n", asset.pointer.c_str(), asset.path.c_str(),
                asset.summary.c_str());
  MemoryEstimate memory = estimate_memory(scene, settings);
  memory.textures = request.texture_bytes;
  print_memory(memory, true);
  return 0;
}

// ---- mesh files ------------------------------------------------------------------------------

int print_mesh_file(const std::string& file) {
  MeshFile mesh_file;
  try {
    mesh_file = read_mesh_file(file, file);
  } catch (const MeshFileError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  const MeshDesc& mesh = mesh_file.mesh;
  for (const std::string& warning : mesh_file.warnings)
    std::fprintf(stderr, "warning: %s\n", warning.c_str());
  const int64_t triangles = int64_t(mesh.indices.size() / 3);
  // Degenerate as the scene loader judges them, here in the file's own coordinates.
  int64_t degenerate = 0;
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const vec3 a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
               c = mesh.positions[mesh.indices[t + 2]];
    const double area = glm::length(glm::cross(dvec3(b) - dvec3(a), dvec3(c) - dvec3(a)));
    if (!(area > 0) || float(area) == 0.f) ++degenerate;
  }
  vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (const vec3& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  std::string format = fs::path(file).extension().string().substr(1);
  std::transform(format.begin(), format.end(), format.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  std::printf("%s: mesh file (%s)\n", file.c_str(), format.c_str());
  std::printf("  faces       %lld\n", static_cast<long long>(mesh_file.faces));
  std::printf("  triangles   %lld (%lld degenerate, dropped when rendered)\n",
              static_cast<long long>(triangles), static_cast<long long>(degenerate));
  std::printf("  vertices    %zu\n", mesh.positions.size());
  std::printf("  normals     %s\n", mesh.normals.empty() ? "no (shaded flat)" : "yes");
  std::printf("  uvs         %s\n", mesh.uvs.empty() ? "no" : "yes");
  std::printf("  bounds      [%g, %g, %g] to [%g, %g, %g]\n", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
  print_memory(estimate_mesh_memory(mesh), false);
  return 0;
}

struct FileKind {
  bool (*matches)(const fs::path&);
  int (*print)(const std::string&);
};
const FileKind kKinds[] = {
    {is_scene, print_scene},
    {is_gltf, print_scene},
    {is_mesh_file_name, print_mesh_file},
};

}  // namespace

int run_info(int argc, char** argv) {
  int exit_code = 0;
  const auto files = file_arguments(argc, argv, "info", print_help, &exit_code);
  if (!files) return exit_code;
  int status = 0;
  for (const std::string& file : *files) {
    const auto kind = std::find_if(std::begin(kKinds), std::end(kKinds),
                                   [&](const FileKind& k) { return k.matches(file); });
    if (kind == std::end(kKinds)) {
      std::fprintf(stderr,
                   "%s: unknown kind of file: expected a scene (.json), a glTF asset (.gltf, "
                   ".glb) or a mesh (.ply, .obj)\n",
                   file.c_str());
      status = 1;
      continue;
    }
    if (kind->print(file) != 0) status = 1;
  }
  return status;
}

}  // namespace penumbra::app
