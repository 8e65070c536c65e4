#pragma once
// `penumbra serve`: the HTTP render service.
namespace penumbra::server {
// argv[0] is "serve". Returns the process exit code.
int run_serve(int argc, char** argv);
}  // namespace penumbra::server
