// penumbra: render, validate, info, serve, bench.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "api/version.h"
#include "app/commands.h"
#ifdef PENUMBRA_HAVE_SERVER
#include "server/serve_command.h"
#endif
#ifdef PENUMBRA_SERVE_BINARY
#include <unistd.h>

#include "renderer/io/executable_dir.h"
#endif

namespace {
void print_usage(std::FILE* out) {
  std::fprintf(out,
               "usage: penumbra <command> [options]\n"
               "\n"
               "commands:\n"
               "  render SCENE.json -o OUT.{png,exr}   render a scene to an image\n"
               "  merge PART.exr... -o OUT.exr         join windows of a frame rendered apart (render --window)\n"
               "  validate SCENE.json...               check scenes, print every error with its JSON pointer\n"
               "  info FILE...                         what a scene or mesh file contains, and its memory\n"
#if defined(PENUMBRA_HAVE_SERVER) || defined(PENUMBRA_SERVE_BINARY)
               "  serve                                run the HTTP render service\n"
#endif
               "  bench                                measure renderer rays/s against Embree alone\n"
               "\n"
               "Run 'penumbra <command> --help' for the options of a command.\n");
}
#ifdef PENUMBRA_SERVE_BINARY
// `penumbra serve`: the service binary beside this one, in this process (exec keeps the pid,
// so signals and supervisors see no difference), with the same arguments.
int exec_serve(char** argv) {
  const std::string dir = penumbra::executable_dir();
  const std::string path = (dir.empty() ? std::string(".") : dir) + "/" + PENUMBRA_SERVE_BINARY;
  std::vector<char*> args(argv, argv + 1);
  while (argv[args.size()]) args.push_back(argv[args.size()]);
  args[0] = const_cast<char*>(path.c_str());
  args.push_back(nullptr);
  ::execv(path.c_str(), args.data());
  std::fprintf(stderr, "penumbra serve: error: cannot run the service binary %s: %s\n",
               path.c_str(), std::strerror(errno));
  return 1;
}
#endif
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    print_usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  try {
    if (command == "render") return penumbra::app::run_render(argc - 1, argv + 1);
    if (command == "merge") return penumbra::app::run_merge(argc - 1, argv + 1);
    if (command == "validate") return penumbra::app::run_validate(argc - 1, argv + 1);
    if (command == "info") return penumbra::app::run_info(argc - 1, argv + 1);
    if (command == "bench") return penumbra::app::run_bench(argc - 1, argv + 1);
#ifdef PENUMBRA_HAVE_SERVER
    if (command == "serve") return penumbra::server::run_serve(argc - 1, argv + 1);
#elif defined(PENUMBRA_SERVE_BINARY)
    if (command == "serve") return exec_serve(argv);
#endif
    if (command == "--version") {
      std::printf("%s\n", penumbra::api::kSoftwareName);
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "penumbra %s: error: %s\n", command.c_str(), e.what());
    return 1;
  }
  std::fprintf(stderr, "penumbra: unknown command '%s'\n\n", command.c_str());
  print_usage(stderr);
  return 2;
}
