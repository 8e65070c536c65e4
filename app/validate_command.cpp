// `penumbra validate SCENE.json...`: checks scenes without rendering them.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <variant>
#include <vector>

#include "api/scene_loader.h"
#include "app/commands.h"
#include "app/load_report.h"
#include "app/option_parsing.h"

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
  int exit_code = 0;
  const auto files = file_arguments(argc, argv, "validate", print_help, &exit_code);
  if (!files) return exit_code;

  bool all_valid = true;
  for (const std::string& file : *files) {
    const api::LoadResult result = api::load_scene_file(file);
    if (!report_load_problems(file, result)) {
      all_valid = false;
      continue;
    }
    const SceneInput& scene = result.request->scene;
    const auto emitters = std::count_if(scene.objects.begin(), scene.objects.end(),
                                        [](const ObjectDesc& o) { return !is_black(o.emission); });
    size_t copies = 0;  // placed by instances objects, which are objects too
    for (const InstancesDesc& set : scene.instances) copies += set.transforms.size();
    const std::string instanced =
        scene.instances.empty() ? "" : ", " + std::to_string(copies) + " instanced copies";
    std::printf("%s: OK (%zu objects, %lld triangles, %zu lights, %lld emitting objects%s)\n",
                file.c_str(), scene.objects.size() + scene.instances.size(),
                static_cast<long long>(count_triangles(scene)), scene.lights.size(),
                static_cast<long long>(emitters), instanced.c_str());
  }
  return all_valid ? 0 : 1;
}

}  // namespace penumbra::app
