// `penumbra validate SCENE.json...`: checks scenes without rendering them.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <variant>
#include <vector>

#include "api/scene_loader.h"
#include "app/commands.h"

namespace penumbra::app {

namespace {

void print_help(std::FILE* out) {
  std::fprintf(out,
               "usage: penumbra validate SCENE.json [MORE.json ...]\n"
               "\n"
               "Checks each scene against scene format v1 without rendering it. Every problem is\n"
               "printed to stderr as '<file>: /json/pointer: message' (warnings prefixed with\n"
               "'warning:'); a valid scene prints '<file>: OK' with its counts to stdout.\n"
               "\n"
               "exit status: 0 all scenes valid, 1 some scene invalid, 2 usage error\n");
}

int64_t count_triangles(const SceneInput& scene) {
  int64_t triangles = 0;
  for (const ObjectDesc& object : scene.objects)
    if (const auto* mesh = std::get_if<MeshDesc>(&object.shape))
      triangles += int64_t(mesh->indices.size() / 3);
  return triangles;
}

}  // namespace

int run_validate(int argc, char** argv) {
  std::vector<std::string> files;
  bool options_done = false;
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    if (!options_done && (!std::strcmp(arg, "--help") || !std::strcmp(arg, "-h"))) {
      print_help(stdout);
      return 0;
    }
    if (!options_done && !std::strcmp(arg, "--")) {
      options_done = true;
      continue;
    }
    if (!options_done && arg[0] == '-' && arg[1] != '\0') {
      std::fprintf(stderr, "penumbra validate: unknown option '%s'\n", arg);
      print_help(stderr);
      return 2;
    }
    files.emplace_back(arg);
  }
  if (files.empty()) {
    print_help(stderr);
    return 2;
  }

  bool all_valid = true;
  for (const std::string& file : files) {
    const api::LoadResult result = api::load_scene_file(file);
    for (const api::Diagnostic& warning : result.warnings)
      std::fprintf(stderr, "%s: warning: %s\n", file.c_str(), warning.to_string().c_str());
    for (const api::Diagnostic& error : result.errors)
      std::fprintf(stderr, "%s: %s\n", file.c_str(), error.to_string().c_str());
    if (!result.ok()) {
      all_valid = false;
      continue;
    }
    const SceneInput& scene = result.request->scene;
    const auto emitters = std::count_if(scene.objects.begin(), scene.objects.end(),
                                        [](const ObjectDesc& o) { return !is_black(o.emission); });
    std::printf("%s: OK (%zu objects, %lld triangles, %zu lights, %lld emitting objects)\n",
                file.c_str(), scene.objects.size(), static_cast<long long>(count_triangles(scene)),
                scene.lights.size(), static_cast<long long>(emitters));
  }
  return all_valid ? 0 : 1;
}

}  // namespace penumbra::app
