#pragma once
// Real stores behind a gate a test can close: GatedJobStore blocks in apply() (a commit that
// takes as long as the test wants), GatedResultStore blocks in remove() (a slow file deletion).
// They decorate the real SQLite and file stores; nothing of the service is replaced.
#include <chrono>
#include <condition_variable>
#include <mutex>

#include "server/storage/job_store.h"
#include "server/storage/result_store.h"

namespace penumbra::test {

class Gate {
 public:
  void close() {
    std::lock_guard lock(mutex_);
    open_ = false;
  }
  void open() {
    {
      std::lock_guard lock(mutex_);
      open_ = true;
    }
    cv_.notify_all();
  }
  // Blocks while the gate is closed.
  void pass() {
    std::unique_lock lock(mutex_);
    ++arrived_;
    cv_.notify_all();
    cv_.wait(lock, [&] { return open_; });
  }
  // True once `n` callers have reached pass() (blocked or through), false after the timeout.
  bool wait_arrived(int n, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return arrived_ >= n; });
  }
  int arrived() {
    std::lock_guard lock(mutex_);
    return arrived_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = true;
  int arrived_ = 0;
};

class GatedJobStore final : public server::JobStore {
 public:
  GatedJobStore(server::JobStore& inner, Gate& gate) : inner_(inner), gate_(gate) {}
  server::StoredJobs load() override { return inner_.load(); }
  std::optional<std::string> scene(const std::string& id) override { return inner_.scene(id); }
  void apply(const std::vector<server::JobChange>& changes) override {
    gate_.pass();
    inner_.apply(changes);
  }

 private:
  server::JobStore& inner_;
  Gate& gate_;
};

class GatedResultStore final : public server::ResultStore {
 public:
  GatedResultStore(server::ResultStore& inner, Gate& gate) : inner_(inner), gate_(gate) {}
  void write(const std::string& id, const std::string& format,
             const std::vector<uint8_t>& bytes) override {
    inner_.write(id, format, bytes);
  }
  std::optional<server::StoredResult> open(const std::string& id,
                                           const std::string& format) const override {
    return inner_.open(id, format);
  }
  void remove(const std::string& id) override {
    gate_.pass();
    inner_.remove(id);
  }

 private:
  server::ResultStore& inner_;
  Gate& gate_;
};

}  // namespace penumbra::test
