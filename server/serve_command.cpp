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

#include "server/farm/farm_schema.h"
#include "server/farm/farm_service.h"
#include "server/farm/farm_worker.h"
#include "server/farm/pg_pool.h"
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
  FileResultStore files(config.data_dir, /*shared=*/config.farm());
  Metrics metrics;
  AssetStore assets(config.data_dir, {config.max_asset_bytes, config.max_asset_store_bytes},
                    /*shared=*/config.farm());
  // One node (SQLite in --data-dir) or a farm node (PostgreSQL, --data-dir shared): the routes
  // see a JobBackend either way.
  std::unique_ptr<SqliteJobStore> sqlite;
  std::unique_ptr<JobService> local;
  std::unique_ptr<PgPool> pool;
  std::unique_ptr<FarmService> farm;
  std::unique_ptr<FarmWorker> farm_worker;
  JobBackend* backend = nullptr;
  if (config.farm()) {
    try {
      PgConnection db(config.store);
      const int version = migrate_farm_schema(db);
      std::printf("store %s, schema version %d, role %s\n", redact_url(config.store).c_str(),
                  version, config.role.c_str());
    } catch (const StoreError& e) {
      std::fprintf(stderr, "penumbra serve: %s\n", e.what());
      return 1;
    }
    pool = std::make_unique<PgPool>(config.store, 8);
    farm = std::make_unique<FarmService>(config, *pool, files, metrics, &assets);
    if (config.renders()) farm_worker = std::make_unique<FarmWorker>(config, files, metrics);
    backend = farm.get();
  } else {
    sqlite = std::make_unique<SqliteJobStore>((std::filesystem::path(config.data_dir) / "jobs.db").string());
    local = std::make_unique<JobService>(config, *sqlite, files, metrics, &assets);
    backend = local.get();
  }
  HttpServer http(config, *backend, metrics);
  const int port = http.bind();
  if (port <= 0) {
    std::fprintf(stderr, "penumbra serve: cannot listen on %s:%d\n", config.host.c_str(), config.port);
    return 1;
  }
  if (open_without_token && !http.bound_to_loopback()) return refuse_open();
  if (local) local->start();
  if (farm) {
    farm->start();
    if (farm_worker) {
      try {
        farm_worker->start();
      } catch (const StoreError& e) {
        std::fprintf(stderr, "penumbra serve: %s\n", e.what());
        return 1;
      }
    }
  }

  std::atomic<bool> shutting_down{false};
  std::atomic<bool> listen_returned{false};
  std::thread signal_thread([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    shutting_down = true;
    const auto start = std::chrono::steady_clock::now();
    std::fprintf(stderr, "penumbra serve: %s: shutting down\n", sig == SIGINT ? "SIGINT" : "SIGTERM");
    http.set_ready(false);
    if (farm) {
      // Running renders stop and their tasks go back to the queue for other workers.
      farm->begin_shutdown();
      if (farm_worker) farm_worker->begin_shutdown();
      if (farm_worker) farm_worker->join();
      farm->stop();
    }
    if (local) local->begin_shutdown();
    if (local && !local->stop(start + kShutdownBudget)) {
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
