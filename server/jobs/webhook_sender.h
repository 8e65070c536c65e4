#pragma once
// Delivers the webhook of a job that reached its final state: POST of the job's JSON to the
// job's notify.url, signed (webhook_signature.h), with an idempotency id that stays the same
// across retries and restarts (X-Penumbra-Delivery: <job id>-<state>), retried with exponential
// backoff and jitter until --webhook-retry-for after the job ended. At least once: the delivery
// status is part of the job's record (JobRecord::Notify, committed by the store writer), and
// every finished job whose webhook is neither delivered nor given up is scheduled again at
// startup, so a kill -9 between the job's end and the receiver's 2xx repeats the POST.
//
// Each attempt resolves the host itself, checks the allow list again (it may have changed
// since the job was accepted) and connects to the address it resolved (no second lookup a DNS
// answer could change in between); redirects are not followed; at most kMaxAnswerBytes of the
// answer are read. The secret is never logged.
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "server/jobs/webhook_url.h"
#include "server/metrics.h"
#include "server/storage/job_record.h"

namespace penumbra::server {

struct WebhookSettings {
  std::vector<AllowedHost> allowed;
  double timeout_seconds = 10;
  double retry_seconds = 3600;  // after the job's finished_at
  int threads = 2;
};

// The delay before retry number `attempts` + 1 (attempts >= 1 made so far): 1 s, 2 s, 4 s ...
// capped at 5 min, with "equal jitter" (half fixed, half uniform; AWS Architecture Blog,
// "Exponential Backoff and Jitter", 2015) so receivers coming back are not hit in lockstep.
double webhook_backoff_seconds(int attempts, double unit_random);

class WebhookSender {
 public:
  struct Hooks {
    // The job's record now; nullopt when it is gone.
    std::function<std::optional<JobRecord>(const std::string& id)> find;
    // The JSON body for the job (what GET /v1/jobs/{id} answers, without the delivery status).
    std::function<std::string(const JobRecord&)> body;
    // Records a delivery status in the job (durably, through the job table).
    std::function<void(const std::string& id, const JobRecord::Notify& status)> save;
  };

  static constexpr std::size_t kMaxAnswerBytes = 64 * 1024;

  WebhookSender(WebhookSettings settings, Metrics& metrics);
  ~WebhookSender();
  WebhookSender(const WebhookSender&) = delete;
  WebhookSender& operator=(const WebhookSender&) = delete;

  void start(Hooks hooks);
  // Due at this Unix time (or now if earlier). A job already scheduled keeps the earlier time.
  // Takes only this class's lock (it is called from the job table's observer).
  void schedule(const std::string& id, double due_unix);
  // Whether this record has a webhook still to deliver.
  static bool pending(const JobRecord& r);
  // Deliveries waiting (scheduled or in flight).
  std::size_t backlog() const;
  void stop();

 private:
  void loop();
  void deliver(const std::string& id);

  const WebhookSettings settings_;
  Metrics& metrics_;
  Hooks hooks_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::map<std::string, double> due_;  // job id -> Unix time
  std::size_t in_flight_ = 0;
  std::set<std::string> in_flight_ids_;
  std::map<std::string, double> reschedule_;  // retries decided by attempts under way
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace penumbra::server
