#include "server/serve_command.h"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <pthread.h>
#include <sys/resource.h>
#include <thread>
#include <unistd.h>

#include "server/http/http_server.h"
#include "server/jobs/job_service.h"
#include "server/loopback.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/storage/file_result_store.h"
#include "server/storage/sqlite_job_store.h"

namespace penumbra::server {
namespace {

// Well inside the 30 s an orchestrator gives between SIGTERM and SIGKILL.
constexpr auto kShutdownBudget = std::chrono::seconds(20);

std::string url_host(const std::string& host) {
  return host.find(':') != std::string::npos && host.front() != '[' ? "[" + host + "]" : host;
}

}  // namespace

int run_serve(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  const ConfigParse parsed = parse_server_config(args, [](const char* name) { return std::getenv(name); });
  if (parsed.help) {
    std::fputs(serve_usage(), stdout);
    return 0;
  }
  if (!parsed.config) {
    std::fprintf(stderr, "penumbra serve: %s\n\n%s", parsed.error.c_str(), serve_usage());
    return 2;
  }
  const ServerConfig config = *parsed.config;
  // Decided on the addresses the host resolves to, and once more on the address actually bound.
  const bool open_without_token = config.token.empty() && !config.insecure;
  const auto refuse_open = [&config] {
    std::fprintf(stderr,
                 "penumbra serve: refusing to listen on %s without a token: it is not a loopback "
                 "address (decided on the addresses it resolves to), so anyone who can reach it "
                 "could use it.\nSet --token (or PENUMBRA_TOKEN), or pass --insecure if a "
                 "proxy in front authenticates.\n",
                 config.host.c_str());
    return 2;
  };
  if (open_without_token && !is_loopback_host(config.host)) return refuse_open();

  // One descriptor per connection: --http-threads connections need more than the usual soft
  // limit of 1024, so the soft limit is raised to the hard one.
  if (rlimit nofile{}; ::getrlimit(RLIMIT_NOFILE, &nofile) == 0 && nofile.rlim_cur < nofile.rlim_max) {
    nofile.rlim_cur = nofile.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &nofile);
  }

  // Signals are taken by one thread with sigwait; every other thread (created after this)
  // inherits the mask, so no handler runs at an arbitrary point of the render.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::filesystem::create_directories(config.data_dir);
  SqliteJobStore store((std::filesystem::path(config.data_dir) / "jobs.db").string());
  FileResultStore files(config.data_dir);
  Metrics metrics;
  AssetStore assets(config.data_dir, {config.max_asset_bytes, config.max_asset_store_bytes});
  JobService jobs(config, store, files, metrics, &assets);
  HttpServer http(config, jobs, metrics);
  const int port = http.bind();
  if (port <= 0) {
    std::fprintf(stderr, "penumbra serve: cannot listen on %s:%d\n", config.host.c_str(), config.port);
    return 1;
  }
  if (open_without_token && !http.bound_to_loopback()) return refuse_open();
  jobs.start();

  std::atomic<bool> shutting_down{false};
  std::atomic<bool> listen_returned{false};
  std::thread signal_thread([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    shutting_down = true;
    const auto start = std::chrono::steady_clock::now();
    std::fprintf(stderr, "penumbra serve: %s: shutting down\n", sig == SIGINT ? "SIGINT" : "SIGTERM");
    http.set_ready(false);
    jobs.begin_shutdown();
    if (!jobs.stop(start + kShutdownBudget)) {
      // A render that does not stop (e.g. inside a long scene build): its job is still
      // 'running' in the store and runs again after the restart.
      std::fprintf(stderr, "penumbra serve: a render did not stop in time; exiting anyway\n");
      std::fflush(stderr);
      _exit(1);
    }
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(config.drain_seconds)));
    // stop() is a no-op until listen() has started running: a signal right after startup
    // would otherwise leave listen() blocked for good. Repeat until it has returned.
    while (!listen_returned) {
      http.stop();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });

  std::printf("listening on http://%s:%d\n", url_host(config.host).c_str(), port);
  std::printf("data dir %s, %d worker(s) x %d thread(s), queue %d, token %s\n",
              config.data_dir.c_str(), config.workers, config.threads_per_job(), config.max_queue,
              config.token.empty() ? "off" : "on");
  std::fflush(stdout);
  const bool ok = http.listen();
  listen_returned = true;
  if (!shutting_down) {
    // listen() failed on its own: wake the signal thread so it shuts the jobs down.
    pthread_kill(signal_thread.native_handle(), SIGTERM);
  }
  signal_thread.join();
  std::fprintf(stderr, "penumbra serve: stopped\n");
  return ok ? 0 : 1;
}

}  // namespace penumbra::server
