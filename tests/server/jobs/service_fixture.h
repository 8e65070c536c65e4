#pragma once
// A JobService in this process on a temporary data directory: the real SQLite store and result
// files, optionally behind gates (gated_stores.h). No HTTP, no forked binary.
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "server/jobs/job_service.h"
#include "server/storage/file_result_store.h"
#include "server/storage/sqlite_job_store.h"
#include "tests/server/jobs/gated_stores.h"
#include "tests/server/test_support.h"

namespace penumbra::test {

inline server::ServerConfig service_config(const std::string& data_dir) {
  server::ServerConfig c;
  c.data_dir = data_dir;
  c.workers = 1;
  c.render_threads = 1;
  c.max_queue = 100;
  return c;
}

// Owns the stores and the service; a second Service on the same directory is a restart.
class Service {
 public:
  explicit Service(const std::string& data_dir,
                   std::optional<server::ServerConfig> config = std::nullopt)
      : config_(config ? *config : service_config(data_dir)),
        sqlite_(data_dir + "/jobs.db"),
        files_(data_dir),
        store_(sqlite_, commit_gate),
        results_(files_, delete_gate),
        service_(std::make_unique<server::JobService>(config_, store_, results_, metrics_)) {
    service_->start();
  }
  server::JobService& operator*() { return *service_; }
  server::JobService* operator->() { return service_.get(); }
  server::SqliteJobStore& sqlite() { return sqlite_; }
  server::FileResultStore& files() { return files_; }
  // Shuts the service down as SIGTERM would and waits for it.
  void stop() {
    service_->begin_shutdown();
    service_->stop(std::chrono::steady_clock::now() + std::chrono::seconds(30));
  }

  Gate commit_gate;  // closed: every commit blocks
  Gate delete_gate;  // closed: every result deletion blocks

 private:
  server::ServerConfig config_;
  server::SqliteJobStore sqlite_;
  server::FileResultStore files_;
  GatedJobStore store_;
  GatedResultStore results_;
  server::Metrics metrics_;
  std::unique_ptr<server::JobService> service_;
};

inline std::string submit_ok(server::JobService& s, const Json& scene,
                             const std::string& key = "") {
  const server::SubmitOutcome o = s.submit(scene.dump(), key);
  if (o.kind != server::SubmitOutcome::Kind::kAccepted) throw std::runtime_error("submit refused");
  return o.record.id;
}

// Polls the job until `done(state)`; returns the last view (nullopt once the job is gone).
template <class Done>
std::optional<server::JobView> wait_until(
    server::JobService& s, const std::string& id, Done done,
    std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    auto v = s.view(id);
    if (!v || done(v->record.state) || std::chrono::steady_clock::now() > deadline) return v;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

inline std::optional<server::JobView> wait_for_state(server::JobService& s, const std::string& id,
                                                     server::JobState state) {
  return wait_until(s, id, [state](server::JobState st) { return st == state; });
}

}  // namespace penumbra::test
