#pragma once
// Subcommands of the `penumbra` executable. Each takes argv with argv[0] = the subcommand name
// and returns the process exit code.
namespace penumbra::app {
int run_render(int argc, char** argv);
int run_merge(int argc, char** argv);
int run_validate(int argc, char** argv);
int run_info(int argc, char** argv);
int run_bench(int argc, char** argv);
}  // namespace penumbra::app
